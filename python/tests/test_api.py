"""raytrail.Scene: inputs of every accepted shape, dtype and order; errors; the no-copy path;
pickling; the GIL released while tracing."""

import pathlib
import pickle
import threading
import time

import numpy as np
import pytest

import raytrail
from raytrail import _raytrail

from conftest import SCENES

TRI_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
TRI_F = np.array([[0, 1, 2]])
# Two rays: one hits the triangle at t=1 (u=0.25, v=0.5), one misses.
O = np.array([[0.25, 0.5, 1.0], [2.0, 2.0, 1.0]])
D = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])


def check_two(h):
    assert h.t.dtype == np.float32 and h.prim.dtype == np.int64
    assert h.u.dtype == np.float32 and h.v.dtype == np.float32
    assert h.t.tolist() == [1.0, np.inf]
    assert h.prim.tolist() == [0, -1]
    assert h.u.tolist() == [0.25, 0.0] and h.v.tolist() == [0.5, 0.0]


def packed(o, d, tmin=0.0, tmax=np.inf, dtype=np.float32):
    rays = np.empty((len(o), 8), dtype=dtype)
    rays[:, 0:3], rays[:, 3], rays[:, 4:7], rays[:, 7] = o, tmin, d, tmax
    return rays


@pytest.mark.parametrize("vdtype", [np.float32, np.float64, np.int32, np.int64])
@pytest.mark.parametrize("fdtype", [np.int8, np.uint8, np.int16, np.uint16, np.int32, np.uint32, np.int64, np.uint64])
@pytest.mark.parametrize("order", ["C", "F"])
def test_scene_dtypes_and_orders(vdtype, fdtype, order):
    scene = raytrail.Scene(np.asarray(TRI_V, dtype=vdtype, order=order), np.asarray(TRI_F, dtype=fdtype, order=order))
    check_two(scene.intersect(O, D))
    assert scene.faces.tolist() == [[0, 1, 2]] and scene.faces.dtype == np.int64
    assert scene.vertices.dtype == np.float32 and scene.vertices.tolist() == TRI_V.tolist()


def test_scene_from_lists_and_views(tri_scene):
    check_two(tri_scene.intersect(O.tolist(), D.tolist()))
    # Strided views (every other row of a bigger array), reversed rows, Fortran order.
    o2 = np.repeat(O, 2, axis=0)[::2]
    d2 = np.asfortranarray(D)
    check_two(tri_scene.intersect(o2, d2))
    h = tri_scene.intersect(O[::-1], D[::-1])
    assert h.prim.tolist() == [-1, 0]
    big = np.zeros((6, 10))
    big[::3, 2:5] = O
    check_two(tri_scene.intersect(big[::3, 2:5], D))


@pytest.mark.parametrize("dtype", [np.float16, np.float32, np.float64, np.int64, np.dtype(">f4"), np.dtype(">f8")])
def test_ray_dtypes(tri_scene, dtype):
    h = tri_scene.intersect(O.astype(dtype), D.astype(dtype))
    assert h.prim.tolist() == [0, -1]


def test_packed_rays_every_dtype_and_order(tri_scene):
    for dtype in (np.float32, np.float64):
        for order in ("C", "F"):
            check_two(tri_scene.intersect(np.asarray(packed(O, D, dtype=dtype), order=order)))


def test_no_copy_path(tri_scene):
    rays = packed(O, D)
    assert rays.flags.c_contiguous and rays.dtype == np.float32
    before = _raytrail._packed_rays()
    check_two(tri_scene.intersect(rays))
    tri_scene.occluded(rays)
    assert _raytrail._packed_rays() == before, "an (N, 8) float32 C-contiguous array must be traced in place"
    # Every other input is packed once, in one pass: the counter shows it.
    tri_scene.intersect(packed(O, D, dtype=np.float64))
    assert _raytrail._packed_rays() == before + 2
    tri_scene.intersect(np.asfortranarray(rays))
    assert _raytrail._packed_rays() == before + 4
    tri_scene.intersect(O.astype(np.float32), D.astype(np.float32))
    assert _raytrail._packed_rays() == before + 6
    # An unaligned float32 buffer cannot be cast to rays in place: it is copied, not misread.
    raw = np.zeros(rays.nbytes + 1, dtype=np.uint8)
    unaligned = np.frombuffer(raw.data, dtype=np.float32, count=rays.size, offset=1).reshape(rays.shape)
    unaligned[...] = rays
    assert not unaligned.flags.aligned
    check_two(tri_scene.intersect(unaligned))


def test_single_ray(tri_scene):
    h = tri_scene.intersect([0.25, 0.5, 1.0], [0.0, 0.0, -1.0])
    assert h.prim.tolist() == [0] and h.t.tolist() == [1.0]
    h = tri_scene.intersect(packed(O[:1], D[:1])[0])
    assert h.prim.tolist() == [0]
    assert tri_scene.occluded([0.25, 0.5, 1.0], [0.0, 0.0, -1.0]).tolist() == [True]
    t, prim, u, v = tri_scene.intersect(O[:1], D[:1])
    assert (t[0], prim[0], u[0], v[0]) == (1.0, 0, 0.25, 0.5)


def test_bounds_scalars_and_arrays(tri_scene):
    # The hit is at t = 1.
    assert tri_scene.intersect(O, D, tmax=0.5).prim.tolist() == [-1, -1]
    assert tri_scene.intersect(O, D, tmin=1.5).prim.tolist() == [-1, -1]
    assert tri_scene.intersect(O, D, tmin=1.0, tmax=1.0).prim.tolist() == [0, -1]
    assert tri_scene.intersect(O, D, tmax=np.array([0.5, 9.0])).prim.tolist() == [-1, -1]
    assert tri_scene.intersect(O, D, tmax=np.array([1.5, 9.0])).prim.tolist() == [0, -1]
    assert tri_scene.intersect(O, D, tmin=[0.0, 0.0], tmax=np.float32(2)).prim.tolist() == [0, -1]
    assert tri_scene.intersect(O, D, tmin=np.array(2.0)).prim.tolist() == [-1, -1]
    assert tri_scene.intersect(packed(O, D, tmax=0.5)).prim.tolist() == [-1, -1]
    assert tri_scene.occluded(O, D, tmax=[0.5, 9]).tolist() == [False, False]


def test_occluded_matches_intersect(meshes):
    from conftest import rays_at

    for name, mesh in meshes.items():
        scene = raytrail.Scene(mesh.vertices, mesh.faces)
        o, d = rays_at(np.asarray(mesh.vertices), 4000, seed=7)
        for tmax in (np.inf, 0.7):
            h = scene.intersect(o, d, tmax=tmax)
            occ = scene.occluded(o, d, tmax=tmax)
            assert occ.dtype == np.bool_
            np.testing.assert_array_equal(occ, h.prim >= 0, err_msg=name)


def test_every_method_same_hits(meshes):
    from conftest import rays_at

    mesh = meshes["teapot"]
    scene = raytrail.Scene(mesh.vertices, mesh.faces)
    o, d = rays_at(np.asarray(mesh.vertices), 3000, seed=3)
    ref = scene.intersect(o, d)
    assert raytrail.METHODS[0] == "auto" and len(raytrail.METHODS) > 10
    for method in raytrail.METHODS:
        h = scene.intersect(o, d, method=method)
        for a, b, field in zip(h, ref, "t prim u v".split()):
            np.testing.assert_array_equal(a, b, err_msg=f"{method}: {field}")
        np.testing.assert_array_equal(scene.occluded(o, d, method=method), ref.prim >= 0, err_msg=method)


def test_threads_and_repr(tri_scene):
    scene = raytrail.Scene(TRI_V, TRI_F, threads=2)
    assert scene.threads == 2 and tri_scene.threads is None and len(scene) == 1
    check_two(scene.intersect(O, D))
    assert repr(scene) == "raytrail.Scene(3 vertices, 1 faces, threads=2)"


def test_empty_batch(tri_scene):
    for h in (tri_scene.intersect(np.zeros((0, 3)), np.zeros((0, 3))), tri_scene.intersect(np.zeros((0, 8), np.float32))):
        assert all(len(a) == 0 for a in h)
        assert [a.dtype for a in h] == [np.float32, np.int64, np.float32, np.float32]
    assert tri_scene.occluded(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0,)
    # Empty lists are an empty batch too (NumPy reads them as shape (0,)).
    assert len(tri_scene.intersect([], [], tmin=np.zeros(0)).t) == 0


def test_untraceable_rays_are_misses(tri_scene):
    o = np.array([[0.25, 0.5, 1.0]] * 5)
    d = np.array([[0, 0, -1.0], [0, 0, 0], [np.nan, 0, -1], [0, 0, -np.inf], [0, 0, -1]])
    o[4, 0] = np.nan
    h = tri_scene.intersect(o, d)
    assert h.prim.tolist() == [0, -1, -1, -1, -1]
    assert np.isinf(h.t[1:]).all()
    assert tri_scene.occluded(o, d).tolist() == [True, False, False, False, False]
    # tmin > tmax and NaN bounds: misses too.
    assert tri_scene.intersect(O, D, tmin=2.0, tmax=1.0).prim.tolist() == [-1, -1]
    assert tri_scene.intersect(O, D, tmin=np.nan).prim.tolist() == [-1, -1]


def test_refused_rays(tri_scene):
    # Over 2^32 times the scene's size away: no method answers exactly, so the ray is marked.
    h = tri_scene.intersect([[1e30, 0.25, 1.0]], [[-1.0, 0.0, 0.0]])
    assert h.prim.tolist() == [raytrail.REFUSED] and np.isnan(h.t[0])
    with pytest.raises(ValueError, match="REFUSED"):
        tri_scene.occluded([[1e30, 0.25, 1.0]], [[-1.0, 0.0, 0.0]])


@pytest.mark.parametrize(
    "vertices, faces, error, match",
    [
        (TRI_V[:, :2], TRI_F, ValueError, r"vertices: expected shape \(N, 3\), got \(3, 2\)"),
        (TRI_V.ravel(), TRI_F, ValueError, r"vertices: expected shape \(N, 3\), got \(9,\)"),
        (TRI_V, TRI_F[:, :2], ValueError, r"faces: expected shape \(M, 3\), got \(1, 2\)"),
        (TRI_V, TRI_F.astype(np.float64), TypeError, r"faces: expected an integer dtype"),
        (TRI_V, TRI_F.astype(bool), TypeError, r"faces: expected an integer dtype"),
        (TRI_V.astype(complex), TRI_F, TypeError, r"vertices: expected real numbers"),
        (TRI_V.astype(bool), TRI_F, TypeError, r"vertices: expected real numbers"),
        (TRI_V.astype(object), TRI_F, TypeError, r"vertices: expected real numbers"),
        ("abc", TRI_F, TypeError, r"vertices: expected real numbers"),
        ([[0, 0], [1, 0, 0]], TRI_F, TypeError, r"vertices: cannot be read as an array"),
        (np.where([[1, 1, 1], [1, 0, 1], [1, 1, 1]], TRI_V, np.nan), TRI_F, ValueError, r"vertices\[1, 1\] = NaN: not finite"),
        (np.where([[1, 1, 1], [1, 1, 1], [0, 1, 1]], TRI_V, np.inf), TRI_F, ValueError, r"vertices\[2, 0\] = inf: not finite"),
        (TRI_V * 1e39, TRI_F, ValueError, r"beyond float32's range"),
        (TRI_V, [[0, 1, 3]], ValueError, r"faces\[0, 2\] = 3: past the 3 vertices"),
        (TRI_V, [[0, -1, 2]], ValueError, r"faces\[0, 1\] = -1: negative vertex index"),
        (TRI_V, np.array([[0, 1, 2**40]], dtype=np.uint64), ValueError, r"faces\[0, 2\] = 1099511627776: past"),
        (TRI_V, np.zeros((0, 3), int), ValueError, r"faces: the mesh is empty"),
        (np.zeros((0, 3)), np.zeros((0, 3), int), ValueError, r"faces: the mesh is empty"),
        (np.zeros((0, 3)), [], ValueError, r"faces: the mesh is empty"),
        (np.zeros((0, 3)), TRI_F, ValueError, r"faces\[0, 0\] = 0: past the 0 vertices"),
    ],
)
def test_bad_scene(vertices, faces, error, match):
    with pytest.raises(error, match=match):
        raytrail.Scene(vertices, faces)


def test_bad_scene_threads():
    with pytest.raises(ValueError, match="threads"):
        raytrail.Scene(TRI_V, TRI_F, threads=0)
    with pytest.raises((OverflowError, TypeError, ValueError)):
        raytrail.Scene(TRI_V, TRI_F, threads=-1)


@pytest.mark.parametrize(
    "args, kwargs, error, match",
    [
        ((O[:, :2], D), {}, ValueError, r"origins: expected shape \(N, 3\), got \(2, 2\)"),
        ((O, D[:1]), {}, ValueError, r"1 directions"),
        ((O, D.astype(complex)), {}, TypeError, r"directions: expected real numbers"),
        ((O.astype(bool), D), {}, TypeError, r"origins: expected real numbers"),
        ((O, D), {"tmin": [0, 0, 0]}, ValueError, r"tmin: expected a scalar or shape \(2,\)"),
        ((O, D), {"tmax": np.zeros((2, 1))}, ValueError, r"tmax: expected a scalar or shape \(2,\)"),
        ((O, D), {"tmax": np.zeros(1)}, ValueError, r"tmax: expected a scalar or shape \(2,\)"),
        ((O, D), {"tmin": "x"}, TypeError, r"tmin: expected real numbers"),
        ((O, D), {"tmin": True}, TypeError, r"tmin: expected a number"),
        ((O, D), {"method": "nope"}, ValueError, r"method: unknown method \"nope\"; expected one of auto, "),
        ((O,), {}, ValueError, r"rays: without directions the first argument must be a ray array of shape \(N, 8\)"),
        ((packed(O, D),), {"tmax": 1.0}, ValueError, r"tmin, tmax: a ray array \(N, 8\) carries them"),
        ((np.zeros((2, 8, 1), np.float32),), {}, ValueError, r"rays: .*got \(2, 8, 1\)"),
        ((np.zeros((2, 3, 1)), D), {}, ValueError, r"origins: expected shape \(N, 3\)"),
        ((np.float64(1.0), D), {}, ValueError, r"origins: expected shape \(N, 3\), got \(\)"),
        ((None, D), {}, TypeError, r"origins: expected real numbers"),
    ],
)
def test_bad_rays(tri_scene, args, kwargs, error, match):
    with pytest.raises(error, match=match):
        tri_scene.intersect(*args, **kwargs)
    with pytest.raises(error, match=match):
        tri_scene.occluded(*args, **kwargs)


def test_load():
    scene = raytrail.load(SCENES / "teapot.obj")
    assert len(scene) == 6320 and scene.vertices.shape[1] == 3
    scene = raytrail.load(str(SCENES / "cornell_box.obj"), threads=1)
    assert scene.threads == 1 and len(scene) == 36
    with pytest.raises(FileNotFoundError, match="nothing-here.obj"):
        raytrail.load("/nonexistent/nothing-here.obj")
    with pytest.raises(TypeError):
        raytrail.load(3)


def test_load_malformed(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 9\n")
    with pytest.raises(ValueError, match="bad.obj"):
        raytrail.load(bad)
    bad.write_text("v 0 0 0\n")
    with pytest.raises(ValueError):
        raytrail.load(bad)


def test_load_matches_arrays(meshes):
    mesh = meshes["teapot"]
    a = raytrail.load(SCENES / "teapot.obj")
    b = raytrail.Scene(mesh.vertices, mesh.faces)
    from conftest import rays_at

    o, d = rays_at(np.asarray(mesh.vertices), 2000, seed=5)
    np.testing.assert_array_equal(a.intersect(o, d).t, b.intersect(o, d).t)


def test_pickle_round_trip(meshes):
    from conftest import rays_at

    mesh = meshes["teapot"]
    scene = raytrail.Scene(mesh.vertices, mesh.faces, threads=2)
    blob = pickle.dumps(scene, protocol=pickle.HIGHEST_PROTOCOL)
    # Compact: the vertices and faces at 12 bytes each, plus a header; no tree.
    payload = 12 * (len(scene.vertices) + len(scene.faces))
    assert payload <= len(blob) < payload + 1024, len(blob)
    before = raytrail._pickle.unpickled_count()
    again = pickle.loads(blob)
    assert raytrail._pickle.unpickled_count() == before + 1
    assert isinstance(again, raytrail.Scene) and again.threads == 2
    np.testing.assert_array_equal(again.vertices, scene.vertices)
    np.testing.assert_array_equal(again.faces, scene.faces)
    o, d = rays_at(np.asarray(mesh.vertices), 3000, seed=11)
    for a, b in zip(again.intersect(o, d), scene.intersect(o, d)):
        np.testing.assert_array_equal(a, b)
    # Every protocol.
    for protocol in range(2, pickle.HIGHEST_PROTOCOL + 1):
        assert len(pickle.loads(pickle.dumps(scene, protocol=protocol))) == len(scene)


def test_gil_released_while_tracing():
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=5)
    scene = raytrail.Scene(mesh.vertices, mesh.faces)
    rng = np.random.default_rng(0)
    n = 1 << 21
    rays = packed(rng.normal(size=(n, 3)) * 3, rng.normal(size=(n, 3)))
    scene.intersect(rays[:1000])
    done = threading.Event()
    worker = threading.Thread(target=lambda: (scene.intersect(rays), scene.intersect(rays), done.set()))
    start = time.perf_counter()
    worker.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    elapsed = time.perf_counter() - start
    # With the GIL held for the whole call this loop could not run at all until it returned.
    assert ticks >= max(5, 0.2 * elapsed / 0.001), (ticks, elapsed)


def test_concurrent_calls_agree(meshes):
    from conftest import rays_at

    mesh = meshes["icosphere"]
    scene = raytrail.Scene(mesh.vertices, mesh.faces)
    o, d = rays_at(np.asarray(mesh.vertices), 20000, seed=2)
    ref = scene.intersect(o, d)
    results = [None] * 4

    def run(i):
        results[i] = scene.intersect(o, d, method=["auto", "bvh8", "kd-stack", "auto"][i])

    threads = [threading.Thread(target=run, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        np.testing.assert_array_equal(r.t, ref.t)
        np.testing.assert_array_equal(r.prim, ref.prim)


def test_package_surface():
    assert raytrail.__version__ == "0.1.0"
    assert raytrail.Hits._fields == ("t", "prim", "u", "v")
    assert raytrail.Scene.__doc__ and raytrail.Scene.intersect.__doc__ and raytrail.load.__doc__
    assert raytrail.trimesh.RayMeshIntersector.__doc__
    assert (pathlib.Path(raytrail.__file__).parent / "py.typed").exists()
    assert (pathlib.Path(raytrail.__file__).parent / "__init__.pyi").exists()


def test_intersect_all_lists_every_hit_in_order_and_the_first_is_intersect_s():
    # Two parallel triangles, at z = 0 and z = -1; one ray through both, one through neither.
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, -1], [1, 0, -1], [0, 1, -1]], dtype=np.float32)
    scene = raytrail.Scene(v, [[3, 4, 5], [0, 1, 2]])
    o = np.array([[0.25, 0.25, 1.0], [2.0, 2.0, 1.0], [0.25, 0.25, 1.0]])
    d = np.array([[0.0, 0.0, -1.0]] * 3)
    ray, t, prim, u, vv, truncated = scene.intersect_all(o, d)
    assert ray.dtype == np.int64 and prim.dtype == np.int64 and t.dtype == np.float32 and truncated.dtype == np.bool_
    assert ray.tolist() == [0, 0, 2, 2] and prim.tolist() == [1, 0, 1, 0] and t.tolist() == [1.0, 2.0, 1.0, 2.0]
    assert truncated.tolist() == [False, False, False]
    assert np.bincount(ray, minlength=3).tolist() == [2, 0, 2]
    first = scene.intersect(o, d)
    assert first.prim[0] == prim[0] and first.t[0] == t[0]
    cut = scene.intersect_all(o, d, max_hits=1)
    assert cut.prim.tolist() == [1, 1] and cut.truncated.tolist() == [True, False, True]
    short = scene.intersect_all(o, d, tmax=1.5)
    assert short.prim.tolist() == [1, 1]
    none = scene.intersect_all(np.empty((0, 3)), np.empty((0, 3)))
    assert len(none.ray) == 0 and len(none.truncated) == 0


def test_intersect_all_at_a_shared_edge_meets_both_faces_or_one_merged():
    # A unit square of two triangles sharing the diagonal from (0, 0) to (1, 1).
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float32)
    scene = raytrail.Scene(v, [[0, 1, 2], [0, 2, 3]])
    o, d = np.array([[0.5, 0.5, 1.0]]), np.array([[0.0, 0.0, -1.0]])
    both = scene.intersect_all(o, d)
    assert both.prim.tolist() == [0, 1] and both.t.tolist() == [1.0, 1.0]
    merged = scene.intersect_all(o, d, merge_equal_t=True)
    assert merged.prim.tolist() == [0]


def test_nearest_gives_point_distance_and_face_within_the_radius():
    scene = raytrail.Scene(TRI_V, TRI_F)
    pts = np.array([[0.25, 0.25, 2.0], [5.0, 0.0, 0.0], [-1.0, -1.0, 0.0]])
    point, distance, prim, u, v = scene.nearest(pts)
    assert point.shape == (3, 3) and point.dtype == np.float32 and prim.dtype == np.int64
    assert point[0].tolist() == [0.25, 0.25, 0.0] and distance[0] == 2.0 and prim[0] == 0
    assert u[0] == 0.25 and v[0] == 0.25
    assert point[2].tolist() == [0.0, 0.0, 0.0] and np.isclose(distance[2], np.sqrt(2.0))
    near = scene.nearest(pts, radius=3.0)
    assert near.prim.tolist() == [0, -1, 0] and near.distance[1] == np.inf and np.isnan(near.point[1]).all()
    with pytest.raises(ValueError, match="radius"):
        scene.nearest(pts, radius=-1.0)
    with pytest.raises(ValueError, match="points"):
        scene.nearest(np.zeros((2, 2)))
