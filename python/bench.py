#!/usr/bin/env python3
"""Mrays/s of raytrail, embreex and trimesh on the same meshes and rays, per call and with the
conversions included, printed as a markdown table.

    python python/bench.py                       # teapot, a 1.3M-triangle icosphere, and the
                                                 # large meshes in ../shared/scenes if present
    python python/bench.py --rays 262144 --repeat 3 --meshes teapot

Every call starts from what a user holds, float64 (N, 3) origins and directions, and ends with
NumPy hit arrays; so each row counts the conversions each library needs (raytrail packs the
rays itself, embreex gets `astype(float32)` copies, trimesh converts in Python). Columns:

- raytrail: ``Scene(..., threads=2).intersect(origins, directions)``: t, prim, u, v.
- raytrail (8): the same rays handed over as one (N, 8) float32 array, traced without a copy.
- embreex: ``EmbreeScene.run(o32, d32, output=1)``: t, prim, u, v and the normal (Embree's own
  threads: on this 2-core machine, 2).
- trimesh: trimesh's default without embreex, ``ray_triangle.RayMeshIntersector
  .intersects_first`` (the face index only; far fewer rays, see --trimesh-rays: it is slow).

Each cell is the median of --repeat calls after one warm-up call (which also lets Embree build
its tree); the calls of a row's columns are interleaved, so a load on the machine falls on all
of them alike. Rays: primary camera rays (a pinhole camera outside the mesh, looking at its centre,
rows in scanline order) and random rays (origins uniform in the mesh's box grown by half,
directions uniform on the sphere).
"""

import argparse
import os
import pathlib
import platform
import statistics
import sys
import time

import numpy as np

# The installed package, not the source folder beside this script (which lacks the native module).
_HERE = pathlib.Path(__file__).resolve().parent
sys.path[:] = [p for p in sys.path if pathlib.Path(p or ".").resolve() != _HERE]
import raytrail  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[1]


def camera_rays(vertices, n):
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    center, extent = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
    eye = center + np.array([0.35, 0.45, 1.0]) / np.linalg.norm([0.35, 0.45, 1.0]) * 1.3 * extent
    forward = (center - eye) / np.linalg.norm(center - eye)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    side = int(np.sqrt(n))
    ys, xs = np.meshgrid(np.linspace(0.5, -0.5, side), np.linspace(-0.5, 0.5, side), indexing="ij")
    d = forward + 0.8 * (xs.reshape(-1, 1) * right + ys.reshape(-1, 1) * up)
    return np.broadcast_to(eye, d.shape).copy(), d


def random_rays(vertices, n, seed=0):
    rng = np.random.default_rng(seed)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    pad = (hi - lo) * 0.5
    o = lo - pad + rng.random((n, 3)) * (hi - lo + 2 * pad)
    d = rng.normal(size=(n, 3))
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)


def _version(package):
    from importlib.metadata import version

    return version(package)


def timed(fns, repeat):
    """Median seconds per call of each function, the calls interleaved (one of each per round)
    so that a load on the machine falls on all columns alike; one warm-up call each first
    (Embree commits its scene there)."""
    for fn in fns:
        fn()
    times = [[] for _ in fns]
    for _ in range(repeat):
        for fn, ts in zip(fns, times):
            t0 = time.perf_counter()
            fn()
            ts.append(time.perf_counter() - t0)
    return [statistics.median(ts) for ts in times]


def meshes(names, scenes):
    """(name, vertices float64, faces int64, a trimesh mesh or None) for each mesh asked for."""
    out = []
    for name in names:
        if name == "teapot":
            s = raytrail.load(REPO / "conformance" / "scenes" / "teapot.obj")
        elif name.startswith("icosphere"):
            import trimesh

            sub = int(name[len("icosphere") :] or 8)
            m = trimesh.creation.icosphere(subdivisions=sub)
            out.append((f"icosphere({sub})", np.asarray(m.vertices), np.asarray(m.faces), m))
            continue
        else:
            path = next((p for p in sorted(pathlib.Path(scenes).glob(name + ".*")) if not p.name.endswith(".mtl")), None)
            if path is None:
                print(f"# skipped {name}: not in {scenes}", file=sys.stderr)
                continue
            s = raytrail.load(path)
        out.append((name, s.vertices.astype(np.float64), s.faces, None))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rays", type=int, default=1 << 20, help="rays per call (default 1048576)")
    ap.add_argument("--trimesh-rays", type=int, default=2048, help="rays per trimesh call (default 2048)")
    ap.add_argument("--trimesh-max-faces", type=int, default=100_000, help="skip trimesh on larger meshes")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2, help="raytrail's threads (default 2)")
    ap.add_argument("--meshes", default="teapot,icosphere8,bunny,sponza,dragon_vrip")
    ap.add_argument("--scenes", default=os.environ.get("RAYTRAIL_SCENES", REPO.parent / "shared" / "scenes"))
    args = ap.parse_args()

    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError as e:
        rtcore_scene = None
        print(f"# embreex not importable ({e}): its column is empty", file=sys.stderr)
    try:
        import trimesh
        from trimesh.ray import ray_triangle
    except ImportError:
        trimesh = None

    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {platform.python_implementation()} "
          f"{platform.python_version()}, numpy {np.__version__}, raytrail {raytrail.__version__} "
          f"(threads={args.threads})" + (f", embreex {_version('embreex')}" if rtcore_scene else "")
          + (f", trimesh {_version('trimesh')}" if trimesh else ""))
    print(f"command: python {' '.join(sys.argv)}")
    print()
    print("| mesh | triangles | rays | raytrail | raytrail (8) | embreex | trimesh ray_triangle | raytrail / embreex |")
    print("|---|---:|---|---:|---:|---:|---:|---:|")
    for name, v, f, tm in meshes(args.meshes.split(","), args.scenes):
        scene = raytrail.Scene(v, f, threads=args.threads)
        es = None
        if rtcore_scene is not None:
            es = rtcore_scene.EmbreeScene()
            TriangleMesh(scene=es, vertices=v.astype(np.float32), indices=f.astype(np.int32))
        tri = None
        if trimesh is not None and len(f) <= args.trimesh_max_faces:
            tm = tm if tm is not None else trimesh.Trimesh(v, f, process=False)
            tri = ray_triangle.RayMeshIntersector(tm)
            tri.intersects_first(v[:1] + 10, np.ones((1, 3)))  # builds its r-tree
        for kind, make in (("primary", camera_rays), ("random", random_rays)):
            o, d = make(v, args.rays)
            n = len(o)
            rays = np.empty((n, 8), np.float32)
            rays[:, 0:3], rays[:, 3], rays[:, 4:7], rays[:, 7] = o, 0.0, d, np.inf
            calls = [lambda: scene.intersect(o, d), lambda: scene.intersect(rays)]
            if es is not None:
                calls.append(lambda: es.run(o.astype(np.float32), d.astype(np.float32), output=1))
            secs = timed(calls, args.repeat)
            rt, rt8 = n / secs[0] / 1e6, n / secs[1] / 1e6
            em = n / secs[2] / 1e6 if es is not None else None
            if tri is not None:
                k = min(args.trimesh_rays, n)
                idx = np.linspace(0, n - 1, k).astype(int)
                tr = k / timed([lambda: tri.intersects_first(o[idx], d[idx])], max(1, args.repeat // 2))[0] / 1e6
            else:
                tr = None
            cell = lambda x: "n/a" if x is None else f"{x:.2g}" if x < 0.1 else f"{x:.2f}"  # noqa: E731
            ratio = f"{rt / em:.2f}x" if em else "n/a"
            print(f"| {name} | {len(f):,} | {kind} ({n:,}) | {cell(rt)} | {cell(rt8)} | {cell(em)} | {cell(tr)} | {ratio} |",
                  flush=True)


if __name__ == "__main__":
    main()
