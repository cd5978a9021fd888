"""Unpickling of :class:`raytrail.Scene` and :class:`raytrail.InstancedScene`.

A Scene pickles as its vertices (float32, 12 bytes each), its faces (uint32, 12 bytes each) and
its ``threads``; the tree is rebuilt here, on the receiving side, instead of being shipped.
"""

from ._raytrail import InstancedScene, Scene

# Scenes unpickled in this process: lets a test check that dask sends a scene to each worker
# once, not once per chunk.
_unpickled = 0


def scene_from_state(vertices, faces, threads):
    """Rebuilds a pickled Scene (its tree is built again from the triangles)."""
    global _unpickled
    _unpickled += 1
    return Scene(vertices, faces, threads=threads)


def unpickled_count():
    """How many Scenes this process has unpickled."""
    return _unpickled


def instanced_from_state(meshes, mesh, transforms, ids, masks, threads, method):
    """Rebuilds a pickled InstancedScene (each mesh's tree and the top level built again)."""
    return InstancedScene(meshes, mesh, transforms, ids=ids, masks=masks, threads=threads, method=method)
