"""raytrail.InstancedScene: hits against the same triangles flattened into one Scene, ids and
masks (of instances and of rays), pickling, and the errors of bad placements."""

import pickle

import numpy as np
import pytest

import raytrail

from conftest import SCENES


def rotation(axis, angle):
    """The 3x3 rotation by `angle` about the unit vector `axis` (Rodrigues' formula)."""
    x, y, z = axis / np.linalg.norm(axis)
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def grid_placements(n, seed):
    """`n` transforms (n, 3, 4) on a grid, each turned about its own axis and scaled."""
    rng = np.random.default_rng(seed)
    out = np.zeros((n, 3, 4))
    side = int(np.ceil(np.sqrt(n)))
    for k in range(n):
        a = rotation(rng.normal(size=3), rng.uniform(0, 2 * np.pi)) * rng.uniform(0.6, 1.4)
        out[k, :, :3] = a
        out[k, :, 3] = [2.5 * (k % side), 2.5 * (k // side), rng.uniform(-0.5, 0.5)]
    return out


@pytest.fixture(scope="module")
def meshes():
    teapot = raytrail.load(SCENES / "teapot.obj")
    # A unit box of 12 faces, the second mesh.
    v = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.float64) - 0.5
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return [teapot, raytrail.Scene(v, f)]


def flattened(meshes, which, transforms):
    """One Scene of every instance's triangles in the world, and per face its (instance, prim)."""
    vs, fs, owner, offset = [], [], [], 0
    for k, (m, t) in enumerate(zip(which, transforms)):
        mesh = meshes[m]
        # The float32 vertices the instanced scene stores, mapped in float64.
        v = mesh.vertices.astype(np.float64) @ t[:, :3].astype(np.float32).astype(np.float64).T
        vs.append(v + t[:, 3].astype(np.float32))
        fs.append(mesh.faces + offset)
        owner += [(k, p) for p in range(len(mesh))]
        offset += len(v)
    return raytrail.Scene(np.concatenate(vs), np.concatenate(fs)), np.array(owner)


def rays_into(lo, hi, n, seed):
    rng = np.random.default_rng(seed)
    o = lo + (hi - lo) * rng.random((n, 3))
    o[:, 2] = hi[2] + 2.0
    target = lo + (hi - lo) * rng.random((n, 3))
    return o, target - o


def test_matches_flattened(meshes):
    n = 12
    which = np.array([k % 2 for k in range(n)])
    transforms = grid_placements(n, seed=1)
    scene = raytrail.InstancedScene(meshes, which, transforms)
    assert len(scene) == n and scene.ids.tolist() == list(range(n))
    flat, owner = flattened(meshes, which, transforms)
    lo, hi = flat.vertices.min(axis=0), flat.vertices.max(axis=0)
    o, d = rays_into(lo, hi, 20000, seed=2)
    got = scene.intersect(o, d)
    want = flat.intersect(o, d)
    hit = want.prim >= 0
    assert hit.mean() > 0.3, "the rays should mostly hit"
    # Mapped rays and mapped vertices round differently, so a ray within a hair of an edge may
    # land on the neighbouring face (or slip between): those are left out, every other ray must
    # agree exactly on what it hits and closely on where.
    w = np.minimum(np.minimum(want.u, want.v), 1 - want.u - want.v)
    clear = ~hit | (w > 1e-4)
    assert clear.mean() > 0.99
    exp_inst = np.where(hit, owner[np.maximum(want.prim, 0), 0], -1)
    exp_prim = np.where(hit, owner[np.maximum(want.prim, 0), 1], -1)
    np.testing.assert_array_equal(got.instance[clear], exp_inst[clear])
    np.testing.assert_array_equal(got.prim[clear], exp_prim[clear])
    both = clear & hit
    np.testing.assert_allclose(got.t[both], want.t[both], rtol=1e-4)
    np.testing.assert_allclose(got.u[both], want.u[both], atol=1e-3)
    np.testing.assert_array_equal(scene.occluded(o, d), got.prim >= 0)
    assert got.instance.dtype == np.int64 and got.prim.dtype == np.int64 and got.t.dtype == np.float32


def two_boxes(meshes, **kw):
    """The box mesh twice on the z axis: instance 0 at z = 0, instance 1 at z = -3."""
    t = np.zeros((2, 4, 4))
    t[:] = np.eye(4)
    t[1, 2, 3] = -3.0
    return raytrail.InstancedScene(meshes, [1, 1], t, **kw)


DOWN = ([[0.1, 0.2, 5.0]], [[0.0, 0.0, -1.0]])


def test_ids_and_masks(meshes):
    scene = two_boxes(meshes, ids=[7, 4_000_000_000], masks=[0b01, 0b10])
    assert scene.masks.tolist() == [1, 2] and scene.masks.dtype == np.uint32
    h = scene.intersect(*DOWN)
    assert h.instance.tolist() == [7] and h.t.tolist() == [4.5]
    # A ray whose mask leaves the first box out meets the second; one with neither bit, nothing.
    h = scene.intersect(*DOWN, masks=0b10)
    assert h.instance.tolist() == [4_000_000_000] and h.t.tolist() == [7.5]
    h = scene.intersect(*DOWN, masks=np.array([0b100], dtype=np.uint8))
    assert h.instance.tolist() == [-1] and h.prim.tolist() == [-1] and h.t.tolist() == [np.inf]
    assert scene.occluded(*DOWN, masks=[0b100]).tolist() == [False]
    assert scene.occluded(*DOWN, tmax=7.0, masks=[0b10]).tolist() == [False]
    assert scene.occluded(*DOWN, tmax=8.0, masks=[0b10]).tolist() == [True]


def test_pickle_round_trip(meshes):
    scene = two_boxes(meshes, ids=[3, 9], masks=[1, 2], threads=1)
    back = pickle.loads(pickle.dumps(scene))
    assert repr(back) == repr(scene)
    assert back.ids.tolist() == [3, 9] and back.masks.tolist() == [1, 2] and back.threads == 1
    np.testing.assert_array_equal(back.transforms, scene.transforms)
    assert back.intersect(*DOWN).instance.tolist() == [3]


@pytest.mark.parametrize(
    "args, kw, error, words",
    [
        (([], [0], np.eye(4)[None]), {}, ValueError, "meshes: empty"),
        (("x", [0], np.eye(4)[None]), {}, TypeError, "meshes[0]"),
        (([0.5], [0], np.eye(4)[None]), {}, TypeError, "meshes[0]"),
        ((None, [0.0], np.eye(4)[None]), {}, TypeError, "mesh: expected an integer dtype"),
        ((None, [2], np.eye(4)[None]), {}, ValueError, "mesh[0] = 2: out of range"),
        ((None, [-1], np.eye(4)[None]), {}, ValueError, "mesh[0] = -1"),
        ((None, [], np.zeros((0, 4, 4))), {}, ValueError, "no instances"),
        ((None, [0, 1], np.eye(4)[None]), {}, ValueError, "1 transforms for 2 instances"),
        ((None, [0], np.eye(4)), {}, ValueError, "expected shape (K, 3, 4) or (K, 4, 4)"),
        ((None, [0], np.zeros((1, 4, 4))), {}, ValueError, "last row"),
        ((None, [0], np.zeros((1, 3, 4))), {}, ValueError, "not invertible"),
        ((None, [0], np.full((1, 3, 4), np.nan)), {}, ValueError, "not finite"),
        ((None, [0], np.eye(4)[None]), {"ids": [1, 2]}, ValueError, "ids: expected shape (1,)"),
        ((None, [0], np.eye(4)[None]), {"masks": [2**32]}, ValueError, "masks[0] = 4294967296"),
        ((None, [0], np.eye(4)[None]), {"method": "nope"}, ValueError, "unknown method"),
        ((None, [0], np.eye(4)[None]), {"threads": 0}, ValueError, "threads"),
    ],
)
def test_bad_placements(meshes, args, kw, error, words):
    args = (meshes if args[0] is None else args[0],) + args[1:]
    with pytest.raises(error) as e:
        raytrail.InstancedScene(*args, **kw)
    assert words in str(e.value)


def test_bad_ray_masks(meshes):
    scene = two_boxes(meshes)
    with pytest.raises(ValueError, match=r"masks: expected a scalar or shape \(1,\)"):
        scene.intersect(*DOWN, masks=[1, 2])
    with pytest.raises(TypeError, match="masks: expected an integer dtype"):
        scene.intersect(*DOWN, masks=[1.0])
    with pytest.raises(ValueError, match=r"masks = -1: out of range"):
        scene.occluded(*DOWN, masks=-1)


def test_every_method_agrees(meshes):
    which = np.array([0, 1, 0])
    transforms = grid_placements(3, seed=5)
    base = raytrail.InstancedScene(meshes, which, transforms)
    flat, _ = flattened(meshes, which, transforms)
    lo, hi = flat.vertices.min(axis=0), flat.vertices.max(axis=0)
    o, d = rays_into(lo, hi, 2000, seed=6)
    want = base.intersect(o, d)
    for m in raytrail.METHODS:
        if m == "auto":
            continue
        got = raytrail.InstancedScene(meshes, which, transforms, method=m).intersect(o, d)
        # Each method traces the same mapped rays with the same watertight test and tie rule,
        # so every method answers bit for bit alike (as the conformance suite requires).
        np.testing.assert_array_equal(got.instance, want.instance, err_msg=m)
        np.testing.assert_array_equal(got.prim, want.prim, err_msg=m)
        np.testing.assert_array_equal(got.t, want.t, err_msg=m)
