"""The result types of :meth:`raytrail.Scene.intersect`, :meth:`raytrail.Scene.intersect_all`,
:meth:`raytrail.Scene.nearest` and :meth:`raytrail.InstancedScene.intersect`."""

from typing import NamedTuple

import numpy as np


class Hits(NamedTuple):
    """The closest hit of each of N rays, as four arrays of length N (unpack as
    ``t, prim, u, v = scene.intersect(...)``).

    - ``t`` (float32): ray parameter of the hit point ``origin + t * direction`` (in units of the
      direction's length, which need not be 1); ``inf`` for a miss.
    - ``prim`` (int64): index of the face hit; ``-1`` for a miss, ``raytrail.REFUSED`` (-2, with
      ``t`` NaN) for a ray whose origin lies over about 4e9 times the scene's size away.
    - ``u``, ``v`` (float32): barycentric weights of the face's second and third vertex at the
      hit point (the first vertex's weight is ``1 - u - v``); 0 for a miss.
    """

    t: np.ndarray
    prim: np.ndarray
    u: np.ndarray
    v: np.ndarray


class InstanceHits(NamedTuple):
    """The closest hit of each of N rays in an instanced scene (unpack as
    ``t, prim, u, v, instance = scene.intersect(...)``).

    - ``t``, ``u``, ``v``: as in :class:`Hits`.
    - ``prim`` (int64): the face hit, an index into the faces of the instance's mesh; ``-1`` for a
      miss, ``raytrail.REFUSED`` for a ray too far from the scene to answer.
    - ``instance`` (int64): the id of the instance hit (its entry in ``ids``, by default its
      position); ``-1`` for a miss or a refusal.
    """

    t: np.ndarray
    prim: np.ndarray
    u: np.ndarray
    v: np.ndarray
    instance: np.ndarray


class AllHits(NamedTuple):
    """Every hit of each of N rays, as five arrays of length H (the hits of all rays, ray by ray,
    each ray's in order of ``t``) and one of length N (unpack as
    ``ray, t, prim, u, v, truncated = scene.intersect_all(...)``).

    - ``ray`` (int64): the index of the ray each hit belongs to (trimesh's ``index_ray``),
      non-decreasing; ``np.bincount(ray, minlength=N)`` counts each ray's hits.
    - ``t``, ``prim``, ``u``, ``v``: as in :class:`Hits`, one entry per hit (no misses). A ray
      refused as too far from the scene has one entry, ``prim == raytrail.REFUSED``.
    - ``truncated`` (bool, length N): the ray had more hits than ``max_hits`` (its nearest are
      listed).
    """

    ray: np.ndarray
    t: np.ndarray
    prim: np.ndarray
    u: np.ndarray
    v: np.ndarray
    truncated: np.ndarray


class Nearest(NamedTuple):
    """The point of the mesh nearest to each of N query points (unpack as
    ``point, distance, prim, u, v = scene.nearest(points)``).

    - ``point`` (float32, (N, 3)): the nearest point; NaN where none is within the radius.
    - ``distance`` (float32): its distance from the query point; ``inf`` where none.
    - ``prim`` (int64): the face it lies on; ``-1`` where none.
    - ``u``, ``v`` (float32): barycentric weights of the face's second and third vertex at it.
    """

    point: np.ndarray
    distance: np.ndarray
    prim: np.ndarray
    u: np.ndarray
    v: np.ndarray
