"""Big batches on Dask: :func:`intersect` and :func:`occluded` over dask arrays chunked by rows.

>>> import dask, dask.array as da, raytrail, raytrail.dask
>>> hits = raytrail.dask.intersect(scene, origins, directions)   # doctest: +SKIP
>>> t, prim, u, v = dask.compute(*hits)                           # doctest: +SKIP

Each chunk of rows is traced by one task, on whichever worker runs it; the answers are those of
``scene.intersect`` on the whole batch in one process, ray for ray and bit for bit (every
raytrail method finds the same hits, and a ray's hit does not depend on the other rays).

The scene goes to each worker once per call, not once per chunk: on dask.distributed (a client
is given or current) it is scattered to every worker with ``broadcast=True``, and every chunk's
task names that one piece of data; on the local schedulers it is one node of the graph. A Scene
pickles compactly (its vertices and faces; the tree is rebuilt on arrival). To send it once for
many calls, scatter it yourself and pass the future::

    scene_f = client.scatter(scene, broadcast=True)
    hits = raytrail.dask.intersect(scene_f, origins, directions)
"""

import numpy as np

import dask
import dask.array as da

from ._hits import Hits

__all__ = ["intersect", "occluded", "HIT_DTYPE"]

#: The record of one hit in the dask array each call builds (its fields are returned apart).
HIT_DTYPE = np.dtype([("t", np.float32), ("prim", np.int64), ("u", np.float32), ("v", np.float32)])


def _intersect_block(origins, directions, tmin, tmax, scene, method):
    hits = scene.intersect(origins, directions, tmin, tmax, method=method)
    out = np.empty(len(hits.t), dtype=HIT_DTYPE)
    out["t"], out["prim"], out["u"], out["v"] = hits
    return out


def _occluded_block(origins, directions, tmin, tmax, scene, method):
    return scene.occluded(origins, directions, tmin, tmax, method=method)


def _intersect_rays_block(rays, scene, method):
    hits = scene.intersect(rays, method=method)
    out = np.empty(len(hits.t), dtype=HIT_DTYPE)
    out["t"], out["prim"], out["u"], out["v"] = hits
    return out


def _occluded_rays_block(rays, scene, method):
    return scene.occluded(rays, method=method)


def _client(client):
    """The distributed client to scatter to: the one given, else the current one, else None
    (also for ``client=False``: no scattering)."""
    if client is False:
        return None
    if client is not None:
        return client
    try:
        from distributed import get_client
    except ImportError:
        return None
    try:
        return get_client()
    except ValueError:
        return None


def _scene_ref(scene, client):
    """What the tasks name for the scene: a future already, a broadcast future on
    dask.distributed, or one delayed node elsewhere."""
    if type(scene).__name__ == "Future" or hasattr(scene, "__dask_graph__"):
        return scene
    client = _client(client)
    if client is not None:
        return client.scatter(scene, broadcast=True, hash=False)
    return dask.delayed(scene, pure=False, traverse=False)


def _rows(x, name, width=None):
    """`x` as a dask array (a NumPy array becomes one chunked by rows)."""
    if not isinstance(x, da.Array):
        x = np.asarray(x)
        x = da.from_array(x, chunks=(min(max(len(x), 1), 1 << 18),) + x.shape[1:]) if x.ndim else x
    if width is not None and (x.ndim != 2 or x.shape[1] != width):
        raise ValueError(f"{name}: expected shape (N, {width}), got {x.shape}")
    return x


def _bound(b, name, n):
    """A scalar bound as a plain number, a per-ray one as a (n,) dask array."""
    if b is None or np.ndim(b) == 0 and not isinstance(b, da.Array):
        return b, None
    b = _rows(b, name)
    if b.shape != (n,):
        raise ValueError(f"{name}: expected a scalar or shape ({n},) (one value per ray), got {b.shape}")
    return b, "i"


def _map(block, rays_block, scene, origins, directions, tmin, tmax, method, client, dtype):
    if directions is None:
        if tmin is not None or tmax is not None:
            raise ValueError("tmin, tmax: a ray array (N, 8) carries them in columns 3 and 7; pass them there")
        rays = _rows(origins, "rays", 8)
        ref = _scene_ref(scene, client)
        return da.blockwise(rays_block, "i", rays, "ij", ref, None, method, None, dtype=dtype, concatenate=True)
    origins = _rows(origins, "origins", 3)
    directions = _rows(directions, "directions", 3)
    if origins.shape[0] != directions.shape[0]:
        raise ValueError(
            f"origins and directions: {origins.shape[0]} origins but {directions.shape[0]} directions; "
            "expected one of each per ray"
        )
    n = origins.shape[0]
    tmin, tmin_index = _bound(tmin, "tmin", n)
    tmax, tmax_index = _bound(tmax, "tmax", n)
    ref = _scene_ref(scene, client)
    # "ij" -> "i": each task gets whole rows (chunks along the 3 columns are joined), and the
    # arrays' row chunks are unified, so a task's origins, directions and bounds are the same rays.
    return da.blockwise(
        block, "i",
        origins, "ij", directions, "ij", tmin, tmin_index, tmax, tmax_index, ref, None, method, None,
        dtype=dtype, concatenate=True,
    )  # fmt: skip


def intersect(scene, origins, directions=None, tmin=None, tmax=None, method="auto", client=None):
    """The closest hits of a batch of rays held in dask arrays, traced chunk by chunk.

    Parameters
    ----------
    scene : raytrail.Scene, or a future of one (``client.scatter(scene, broadcast=True)``)
    origins, directions : (N, 3) dask (or NumPy) arrays, chunked by rows; or ``origins`` alone
        an (N, 8) ray array (origin, tmin, direction, tmax), as for :meth:`raytrail.Scene.intersect`.
    tmin, tmax : scalars or (N,) arrays (default 0 and inf).
    method : "auto" or one of ``raytrail.METHODS``.
    client : the dask.distributed client to scatter the scene with (default: the current one,
        if any; compute the results with that client). ``False``: do not scatter, make the
        scene one node of the graph instead (for another scheduler while a client is current).

    Returns
    -------
    Hits(t, prim, u, v) of lazy (N,) dask arrays, as :meth:`raytrail.Scene.intersect` returns;
    compute them together (``dask.compute(*hits)``) so that each chunk is traced once.
    """
    out = _map(_intersect_block, _intersect_rays_block, scene, origins, directions, tmin, tmax, method, client, HIT_DTYPE)
    return Hits(out["t"], out["prim"], out["u"], out["v"])


def occluded(scene, origins, directions=None, tmin=None, tmax=None, method="auto", client=None):
    """Whether anything blocks each ray, over dask arrays (arguments as for :func:`intersect`):
    a lazy (N,) bool dask array."""
    return _map(_occluded_block, _occluded_rays_block, scene, origins, directions, tmin, tmax, method, client, bool)
