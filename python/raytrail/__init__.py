"""raytrail: ray traversal for triangle meshes, NumPy rays in, hits out.

>>> import numpy as np, raytrail
>>> scene = raytrail.Scene([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
>>> hits = scene.intersect([[0.25, 0.25, 1.0]], [[0.0, 0.0, -1.0]])
>>> hits.prim.tolist(), hits.t.tolist()
([0], [1.0])

- :class:`Scene` builds the tree once from vertices and faces (:func:`load` from a mesh file);
  :meth:`Scene.intersect` returns :class:`Hits` ``(t, prim, u, v)``, :meth:`Scene.occluded` a
  bool per ray, :meth:`Scene.intersect_all` every hit along each ray (:class:`AllHits`), :meth:`Scene.nearest`
  the nearest point on the mesh to each query point (:class:`Nearest`). All release the GIL and
  run on all cores.
- :class:`InstancedScene` places meshes many times by affine maps (each tree built once), with
  ids and masks; its :meth:`InstancedScene.intersect` returns :class:`InstanceHits`
  ``(t, prim, u, v, instance)``.
- :mod:`raytrail.trimesh`: ``RayMeshIntersector``, a drop-in for ``mesh.ray`` in trimesh.
- :mod:`raytrail.dask`: ``intersect`` / ``occluded`` over dask arrays chunked by rows, on
  dask.distributed or any other scheduler.

A miss has ``prim == -1`` and ``t == inf``; :data:`REFUSED` (-2) marks a ray too far from the
scene to answer exactly (``t`` NaN). See the package README for the conventions in full.
"""

from ._raytrail import METHODS, REFUSED, InstancedScene, Scene, __version__, load
from ._hits import AllHits, Hits, InstanceHits, Nearest

__all__ = ["Scene", "InstancedScene", "Hits", "InstanceHits", "AllHits", "Nearest", "load", "METHODS", "REFUSED", "__version__", "trimesh", "dask"]


def __getattr__(name):
    # The trimesh and dask layers import their (optional) libraries, so they load on first use:
    # `import raytrail` needs only NumPy, and `raytrail.trimesh` works without an explicit import.
    if name in ("trimesh", "dask"):
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
