"""raytrail.dask on a LocalCluster of two worker processes (loopback only): identical hits to a
single process, ray for ray, and the scene unpickled once per worker."""

import numpy as np
import pytest

import dask
import dask.array as da
from distributed import Client, LocalCluster

import raytrail
import raytrail._pickle
import raytrail.dask
from conftest import rays_at


@pytest.fixture(scope="module")
def client():
    cluster = LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, host="127.0.0.1", dashboard_address=None
    )
    with cluster, Client(cluster) as c:
        yield c


def same(a, b):
    for x, y, field in zip(a, b, "t prim u v".split()):
        assert x.dtype == y.dtype, field
        # Bit for bit: the float32 patterns, not just values within a tolerance.
        np.testing.assert_array_equal(np.asarray(x).view(np.uint8), np.asarray(y).view(np.uint8), err_msg=field)


def test_distributed_identical_and_scene_once(client, meshes):
    mesh = meshes["teapot"]
    scene = raytrail.Scene(mesh.vertices, mesh.faces)
    o, d = rays_at(np.asarray(mesh.vertices), 100_000, seed=21)
    ref = scene.intersect(o, d)
    # Rows in chunks of unequal size, the directions chunked differently (and split by
    # columns): each task still gets whole, matching rows.
    origins = da.from_array(o, chunks=(17_000, 3))
    directions = da.from_array(d, chunks=((30_000, 30_000, 40_000), (2, 1)))
    before = client.run(raytrail._pickle.unpickled_count)
    hits = raytrail.dask.intersect(scene, origins, directions)
    assert all(isinstance(h, da.Array) for h in hits)
    got = dask.compute(*hits)
    same(got, ref)
    after = client.run(raytrail._pickle.unpickled_count)
    assert set(after) == set(before) and len(after) == 2
    # Broadcast: each worker received the scene, and unpickled it once, for all its chunks.
    assert {w: after[w] - before[w] for w in after} == {w: 1 for w in after}
    # The chunks ran on both workers.
    assert origins.numblocks[0] > 2


def test_distributed_bounds_rays_and_occluded(client, meshes):
    mesh = meshes["cornell_box"]
    scene = raytrail.Scene(mesh.vertices, mesh.faces)
    o, d = rays_at(np.asarray(mesh.vertices), 30_000, seed=22)
    tmax = np.random.default_rng(0).random(len(o)) * 2
    scene_f = client.scatter(scene, broadcast=True)
    hits = raytrail.dask.intersect(scene_f, da.from_array(o, chunks=7_000), d, tmin=0.05, tmax=da.from_array(tmax, chunks=9_000))
    same(dask.compute(*hits), scene.intersect(o, d, tmin=0.05, tmax=tmax))
    rays = np.empty((len(o), 8), np.float32)
    rays[:, :3], rays[:, 3], rays[:, 4:7], rays[:, 7] = o, 0.0, d, tmax
    hits = raytrail.dask.intersect(scene_f, da.from_array(rays, chunks=(5_000, 8)), method="bvh8")
    same(dask.compute(*hits), scene.intersect(rays))
    occ = raytrail.dask.occluded(scene, da.from_array(o, chunks=6_000), da.from_array(d, chunks=6_000), tmax=tmax).compute()
    np.testing.assert_array_equal(occ, scene.occluded(o, d, tmax=tmax))


def test_local_scheduler(meshes):
    mesh = meshes["icosphere"]
    scene = raytrail.Scene(mesh.vertices, mesh.faces)
    o, d = rays_at(np.asarray(mesh.vertices), 20_000, seed=23)
    # client=False: no scattering (a client of this module's cluster may be current), the scene
    # is one node of the graph.
    hits = raytrail.dask.intersect(scene, da.from_array(o, chunks=3_000), da.from_array(d, chunks=3_000), client=False)
    with dask.config.set(scheduler="threads"):
        same(dask.compute(*hits), scene.intersect(o, d))
    with dask.config.set(scheduler="sync"):
        same(dask.compute(*hits), scene.intersect(o, d))


def test_dask_errors(meshes):
    scene = raytrail.Scene(meshes["box"].vertices, meshes["box"].faces)
    o = da.zeros((10, 3), chunks=5)
    with pytest.raises(ValueError, match="origins: expected shape"):
        raytrail.dask.intersect(scene, da.zeros((10, 2)), o)
    with pytest.raises(ValueError, match="10 origins but 9 directions"):
        raytrail.dask.intersect(scene, o, da.zeros((9, 3)))
    with pytest.raises(ValueError, match="tmax: expected a scalar or shape"):
        raytrail.dask.intersect(scene, o, o, tmax=da.zeros(9))
    with pytest.raises(ValueError, match="rays: expected shape"):
        raytrail.dask.intersect(scene, o)
