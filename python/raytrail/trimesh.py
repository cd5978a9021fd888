"""A drop-in for trimesh's ray queries, traced by raytrail.

>>> import trimesh, raytrail.trimesh
>>> mesh = trimesh.creation.icosphere()
>>> mesh.ray = raytrail.trimesh.RayMeshIntersector(mesh)
>>> mesh.ray.intersects_first([[0, 0, -5]], [[0, 0, 1]])  # doctest: +SKIP
array([...])

:class:`RayMeshIntersector` has the methods and return conventions of
``trimesh.ray.ray_pyembree.RayMeshIntersector`` (and of ``ray_triangle``'s, whose methods take
the same arguments by keyword): ``intersects_first``, ``intersects_any``, ``intersects_id``,
``intersects_location`` and ``contains_points`` (so ``mesh.contains`` works through it).

Differences, all on the side of exactness:

- Rays start at their origin (``t >= 0``) and are traced in float32 (as embree does); hit
  locations are then computed in float64, where the ray meets the plane of the face hit.
- ``multiple_hits=True`` lists every hit along each ray in one walk (``Scene.intersect_all``): in
  order of ``t`` along each ray, no face twice and none skipped, except that of faces hit at
  exactly the same ``t`` (a ray through an edge or vertex they share) only the lowest index is
  reported: one crossing of the surface, as the parity test of ``contains_points`` counts them.
  trimesh's own loops instead move the origin past each hit by a fixed offset, which can skip a
  close face or repeat one.
"""

import numpy as np

from ._raytrail import Scene

__all__ = ["RayMeshIntersector"]


def _rays(ray_origins, ray_directions):
    """The rays as one (n, 8) float32 array (origin, tmin=0, direction, tmax=inf), which the
    scene traces without another copy."""
    origins = np.asarray(ray_origins, dtype=np.float64)
    directions = np.asarray(ray_directions, dtype=np.float64)
    if origins.shape != directions.shape:
        raise ValueError("Ray origin and direction don't match!")
    origins = origins.reshape((-1, 3)) if origins.size else origins.reshape((0, 3))
    directions = directions.reshape((-1, 3)) if directions.size else directions.reshape((0, 3))
    rays = np.empty((len(origins), 8), dtype=np.float32)
    rays[:, 0:3] = origins
    rays[:, 3] = 0.0
    rays[:, 4:7] = directions
    rays[:, 7] = np.inf
    return origins, directions, rays


class RayMeshIntersector:
    """Ray queries on a trimesh mesh, with trimesh's signatures and return values.

    ``mesh.ray = RayMeshIntersector(mesh)`` makes the mesh's own queries (``mesh.ray.*``,
    ``mesh.contains``) use raytrail. The raytrail :class:`~raytrail.Scene` is built on first use
    and rebuilt when the mesh's vertices or faces change (trimesh's hash of the mesh).

    Parameters
    ----------
    mesh : trimesh.Trimesh
    threads : int or None
        Passed to :class:`raytrail.Scene`: a pool of this many threads, or None for all cores.
    """

    def __init__(self, mesh, threads=None, **kwargs):
        # **kwargs: ray_pyembree's `scale_to_box` is accepted and ignored (raytrail's tests are
        # exact at any scale within float32, so it needs no rescaling).
        self.mesh = mesh
        self._threads = threads
        self._scene = None
        self._scene_key = None

    @property
    def scene(self):
        """The raytrail Scene of the mesh as it is now."""
        key = self.mesh.__hash__()
        if self._scene is None or key != self._scene_key:
            self._scene = Scene(self.mesh.vertices, self.mesh.faces, threads=self._threads)
            self._scene_key = key
        return self._scene

    def intersects_first(self, ray_origins, ray_directions, **kwargs):
        """Index of the first face each ray hits.

        Parameters
        ----------
        ray_origins : (n, 3) float
        ray_directions : (n, 3) float

        Returns
        -------
        triangle_index : (n,) int64
            Index of the face hit, or -1 where the ray hits nothing.
        """
        _, _, rays = _rays(ray_origins, ray_directions)
        return self.scene.intersect(rays).prim

    def intersects_any(self, ray_origins, ray_directions, **kwargs):
        """Whether each ray hits any face.

        Returns
        -------
        hit : (n,) bool
        """
        _, _, rays = _rays(ray_origins, ray_directions)
        return self.scene.occluded(rays)

    def intersects_id(
        self,
        ray_origins,
        ray_directions,
        multiple_hits=True,
        max_hits=100,
        return_locations=False,
        **kwargs,
    ):
        """The faces hit by each ray: the first only, or every hit along it.

        Parameters
        ----------
        ray_origins : (n, 3) float
        ray_directions : (n, 3) float
        multiple_hits : bool
            Every hit along each ray (in order of distance, each face once) or the first only.
        max_hits : int
            At most this many hits per ray.
        return_locations : bool
            Also return the hit points.

        Returns
        -------
        index_tri : (h,) int64
            Index of the face of each hit.
        index_ray : (h,) int64
            Index of the ray of each hit. Hits are ordered by round (every ray's first hit, then
            every second hit, ...), so each ray's hits are in order of distance.
        locations : (h, 3) float64
            The hit points, only with ``return_locations``.
        """
        origins, directions, rays = _rays(ray_origins, ray_directions)
        max_hits = max(int(max_hits), 1) if multiple_hits else 1
        # Every hit in one walk per ray (Scene.intersect_all), each face once. Faces hit at the same
        # t (a ray through an edge or vertex they share) count once, the lowest index: one crossing
        # of the surface, as trimesh's parity test for contains_points needs.
        ray, t, prim, _, _, _ = self.scene.intersect_all(rays, max_hits=max_hits, merge_equal_t=True)
        # A ray refused as too far from the mesh has one entry with prim REFUSED: no hit here.
        keep = prim >= 0
        ray, t, prim = ray[keep], t[keep], prim[keep]
        # By round, as trimesh orders them: every ray's first hit, then every second hit, ...
        rank = np.arange(len(ray)) - np.searchsorted(ray, ray, side="left")
        order = np.lexsort((ray, rank))
        index_tri, index_ray, t = prim[order], ray[order], t[order]
        if not return_locations:
            return index_tri, index_ray
        return index_tri, index_ray, self._locations(origins, directions, index_tri, index_ray, t)

    def _locations(self, origins, directions, index_tri, index_ray, t):
        """Hit points in float64: where each ray meets its face's plane (what trimesh computes),
        falling back to ``origin + t * direction`` for a ray nearly parallel to the plane."""
        o = origins[index_ray]
        d = directions[index_ray]
        tri = np.asarray(self.mesh.vertices, dtype=np.float64)[np.asarray(self.mesh.faces)[index_tri]]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        denom = np.einsum("ij,ij->i", d, n)
        with np.errstate(divide="ignore", invalid="ignore"):
            t_plane = np.einsum("ij,ij->i", tri[:, 0] - o, n) / denom
        t64 = t.astype(np.float64)
        # The plane's t refines the float32 one. Where the ray is nearly edge-on to the plane (or
        # the face is degenerate) it is unreliable: keep the traced t where the two points lie
        # farther apart than a thousandth of the mesh's size.
        dlen = np.linalg.norm(d, axis=1)
        good = np.isfinite(t_plane) & (np.abs(t_plane - t64) * dlen <= 1e-3 * float(self.mesh.scale))
        t64 = np.where(good, t_plane, t64)
        return o + d * t64[:, None]

    def intersects_location(self, ray_origins, ray_directions, multiple_hits=True, **kwargs):
        """Where the rays hit the mesh.

        Returns
        -------
        locations : (h, 3) float64
            The hit points.
        index_ray : (h,) int64
            Index of the ray of each hit.
        index_tri : (h,) int64
            Index of the face of each hit.
        """
        index_tri, index_ray, locations = self.intersects_id(
            ray_origins, ray_directions, multiple_hits=multiple_hits, return_locations=True, **kwargs
        )
        return locations, index_ray, index_tri

    def contains_points(self, points):
        """Whether each point is inside the mesh (trimesh's parity test over these rays); for a
        point on the surface the answer is undefined, as in trimesh."""
        from trimesh.ray.ray_util import contains_points

        return contains_points(self, points)
