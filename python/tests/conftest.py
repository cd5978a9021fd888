"""Shared meshes, rays and the exact float64 reference for the raytrail Python tests."""

import os
import pathlib

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
SCENES = REPO / "conformance" / "scenes"


def trimesh_meshes():
    """The test meshes: trimesh primitives and the repository's small scenes, as trimesh loads
    them (face order as in the file; no merging, so indices match the file's triangles)."""
    import trimesh

    meshes = {
        "icosphere": trimesh.creation.icosphere(subdivisions=3),
        "box": trimesh.creation.box(extents=(1.0, 2.0, 3.0)),
        "cylinder": trimesh.creation.cylinder(radius=1.0, height=2.0, sections=32),
        "annulus": trimesh.creation.annulus(r_min=0.5, r_max=1.0, height=0.5),
        "teapot": trimesh.load(SCENES / "teapot.obj", force="mesh", process=False),
        "cornell_box": trimesh.load(SCENES / "cornell_box.obj", force="mesh", process=False),
    }
    return meshes


def rays_at(vertices, n, seed):
    """`n` rays from a shell around the mesh aimed at points inside its bounds (most hit, some
    miss), plus a few aimed exactly at vertices and edge midpoints (the ties and near-misses
    where tracers tend to differ)."""
    rng = np.random.default_rng(seed)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    center, extent = (lo + hi) / 2, float((hi - lo).max())
    origins = center + rng.normal(size=(n, 3)) * extent
    targets = lo + rng.random((n, 3)) * (hi - lo)
    k = n // 8
    targets[:k] = vertices[rng.integers(0, len(vertices), size=k)]
    return origins, targets - origins


def _moller_trumbore(o, d, v0, v1, v2, eps):
    """Möller-Trumbore in float64 over broadcastable (..., 3) arrays: t, or inf for a miss.
    `eps` widens (> 0) or shrinks (< 0) each triangle by that much in barycentric terms."""
    e1, e2 = v1 - v0, v2 - v0
    shape = np.broadcast_shapes(o.shape, d.shape, v0.shape)
    o, d, e1, e2, v0 = (np.broadcast_to(a, shape) for a in (o, d, e1, e2, v0))
    p = np.cross(d, e2)
    det = np.einsum("...i,...i->...", e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - v0
        u = np.einsum("...i,...i->...", s, p) * inv
        q = np.cross(s, e1)
        v = np.einsum("...i,...i->...", d, q) * inv
        t = np.einsum("...i,...i->...", e2, q) * inv
    ok = (det != 0) & (u >= -eps) & (v >= -eps) & (u + v <= 1 + eps) & (t >= 0) & np.isfinite(t)
    return np.where(ok, t, np.inf)


def exact_t(origins, directions, triangles, eps):
    """Every ray against every triangle: a (rays, triangles) array of t, inf where it misses."""
    o = np.asarray(origins, np.float64)[:, None, :]
    d = np.asarray(directions, np.float64)[:, None, :]
    v0, v1, v2 = (np.asarray(triangles, np.float64)[None, :, i, :] for i in range(3))
    return _moller_trumbore(o, d, v0, v1, v2, eps)


def exact_t_pairs(origins, directions, triangles, eps=np.inf):
    """Ray i against triangle i (triangles (n, 3, 3)): t per ray; by default the ray's t at the
    triangle's plane whatever the edges."""
    tri = np.asarray(triangles, np.float64)
    return _moller_trumbore(np.asarray(origins, np.float64), np.asarray(directions, np.float64), tri[:, 0], tri[:, 1], tri[:, 2], eps)


class Judge:
    """Judges a closest-hit answer to the float32 rays over the float32 vertices (the question
    raytrail and embree answer) against its exact answer (float64 arithmetic on those inputs).

    Float32 tracers subtract the origin from each vertex in float32, which moves the vertices
    by up to about an ulp of the origin's magnitude: so a face counts as hit "loosely" if the ray
    passes within `rel` times (|origin| + the mesh's size) of it, and "robustly" if it passes
    that far inside it. An answer is right where its face is hit loosely and no face is robustly
    hit closer than it (by more than `tol` of the mesh's size), or where it is a miss and no
    face is robustly hit.
    """

    def __init__(self, origins, directions, triangles, rel=1e-6, tol=1e-5):
        f32 = lambda a: np.asarray(a, np.float32).astype(np.float64)  # noqa: E731
        origins, directions, triangles = f32(origins), f32(directions), f32(triangles)
        scale = float(np.ptp(triangles.reshape(-1, 3), axis=0).max())
        # The slack as a distance per ray from the face in space, then in barycentric terms per
        # ray and face: over the face's smallest height (twice its area over its longest edge),
        # and over the sine of the ray's angle to the face's plane (a ray that passes a face's
        # edge by a hair in space meets its plane far outside it when it comes in grazing).
        slack = rel * (np.abs(origins).max(axis=1) + scale)
        e = triangles[:, [1, 2, 0]] - triangles
        longest = np.linalg.norm(e, axis=2).max(axis=1)
        normal = np.cross(e[:, 0], e[:, 1])
        area2 = np.linalg.norm(normal, axis=1)
        height = area2 / np.maximum(longest, 1e-300)
        unit_n = normal / np.maximum(area2, 1e-300)[:, None]
        unit_d = directions / np.maximum(np.linalg.norm(directions, axis=1), 1e-300)[:, None]
        sine = np.abs(unit_d @ unit_n.T)
        eps = slack[:, None] / np.maximum(height[None, :] * sine, 1e-300)
        self.loose = exact_t(origins, directions, triangles, eps)
        self.tight = exact_t(origins, directions, triangles, -eps)
        dlen = np.linalg.norm(directions, axis=1)
        # t is in units of the direction's length; the tolerance is a distance.
        self.tol_t = tol * scale / dlen
        self.closest = self.tight.min(axis=1)

    def right(self, prim):
        prim = np.asarray(prim)
        rows = np.arange(len(prim))
        t_face = np.where(prim >= 0, self.loose[rows, np.maximum(prim, 0)], np.inf)
        hit_ok = np.isfinite(t_face) & (t_face <= self.closest + self.tol_t)
        miss_ok = ~np.isfinite(self.closest)
        return np.where(prim >= 0, hit_ok, miss_ok)


def embreex_or_skip():
    """embreex's scene class, or a skip that says why it is missing (CI installs it from PyPI;
    only a platform without its wheels may skip)."""
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except Exception as e:  # ImportError, or a wheel that does not load on this machine
        reason = f"embreex cannot be imported here ({type(e).__name__}: {e})"
        print("SKIPPED:", reason)
        if os.environ.get("RAYTRAIL_REQUIRE_EMBREEX") == "1":
            pytest.fail(reason + "; RAYTRAIL_REQUIRE_EMBREEX=1 makes that a failure")
        pytest.skip(reason)
    return rtcore_scene, TriangleMesh


@pytest.fixture(scope="session")
def meshes():
    return trimesh_meshes()


@pytest.fixture()
def tri_scene():
    import raytrail

    return raytrail.Scene([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
