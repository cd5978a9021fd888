#!/usr/bin/env python3
"""The Embree table of the benchmark notes (docs/notes/) from `raytrail bench --json` files.

    scripts/embree_table.py NEW.json [NEW.json ...] [--before OLD.json ...]

Per scene, view and ray set: the fastest raytrail CPU method of each run, the medians over the runs
of its Mrays/s, of Embree's and of obvhs CWBVH's, and the medians of the per-run ratios of the
fastest to each (so a ratio is not the ratio of two medians). With --before, a second table gives
the fastest / Embree median of the old runs beside the new ones.
"""
import json
import statistics
import sys

RAYTRAIL_KINDS = ("raytrail-bvh2", "raytrail-kd", "raytrail-wide", "raytrail-stream", "raytrail-auto")


# The pairs issue 13's Done-when names: Sponza from outside and inside, the kitchen from inside, the
# full dragon (its outside framing); camera, shadow, diffuse and ambient-occlusion rays.
NAMED_VIEWS = {("sponza.obj", "outside"), ("sponza.obj", "inside"), ("kitchen.obj", "inside"),
               ("dragon_vrip.ply.gz", "outside")}
NAMED_RAYS = {"primary", "shadow", "diffuse", "ao"}


def named(key):
    """Whether a (scene, view, rays) pair is one the issue names."""
    # An inside view's scene is named "NAME (inside)".
    return (key[0].split(" (")[0], key[1]) in NAMED_VIEWS and key[2] in NAMED_RAYS


def pairs(path):
    """(scene, view, rays) -> (fastest name, its Mrays/s, embree, cwbvh) for one run."""
    out = {}
    with open(path) as f:
        doc = json.load(f)
    for scene in doc["scenes"]:
        for rays in scene["rays"]:
            rows = rays["rows"]
            ours = [r for r in rows if r["kind"] in RAYTRAIL_KINDS]
            peer = {r["target"]: r["mrays_per_s"] for r in rows}
            if not ours or "embree" not in peer or "obvhs-cwbvh" not in peer:
                continue
            best = max(ours, key=lambda r: r["mrays_per_s"])
            key = (scene["name"], scene["view"], rays["type"])
            out[key] = (best["target"], best["mrays_per_s"], peer["embree"], peer["obvhs-cwbvh"])
    return out


def main(argv):
    if not argv or argv[0].startswith("-"):
        sys.exit(__doc__)
    split = argv.index("--before") if "--before" in argv else len(argv)
    new = [pairs(p) for p in argv[:split]]
    old = [pairs(p) for p in argv[split + 1:]]
    med = statistics.median
    print("| scene | view | rays | fastest raytrail (per run) | fastest, Mrays/s | embree | obvhs-cwbvh "
          "| fastest / embree | fastest / cwbvh |")
    print("|---|---|---|---|---|---|---|---|---|")
    at_embree = at_cwbvh = 0
    named_embree = named_cwbvh = named_count = 0
    for key in new[0]:
        runs = [r[key] for r in new if key in r]
        names = [r[0] for r in runs]
        top = max(set(names), key=names.count)
        to_embree = [r[1] / r[2] for r in runs]
        to_cwbvh = [r[1] / r[3] for r in runs]
        e, c = med(to_embree), med(to_cwbvh)
        at_embree += e >= 1.0
        at_cwbvh += c >= 1.5
        if named(key):
            named_count += 1
            named_embree += e >= 1.0
            named_cwbvh += c >= 1.5
        print(f"| {key[0]} | {key[1]} | {key[2]} | {', '.join(names)} | {top} {med([r[1] for r in runs]):.2f} "
              f"| {med([r[2] for r in runs]):.2f} | {med([r[3] for r in runs]):.2f} "
              f"| {e:.2f} ({min(to_embree):.2f}-{max(to_embree):.2f}){' ✓' if e >= 1.0 else ''} "
              f"| {c:.2f} ({min(to_cwbvh):.2f}-{max(to_cwbvh):.2f}){' ✓' if c >= 1.5 else ''} |")
    print(f"\n>= 1.0x Embree: {at_embree} of {len(new[0])}; >= 1.5x CWBVH: {at_cwbvh} of {len(new[0])}")
    print(f"the issue's named pairs: >= 1.0x Embree: {named_embree} of {named_count}; "
          f">= 1.5x CWBVH: {named_cwbvh} of {named_count}")
    if old:
        print("\n| scene | view | rays | before: fastest / embree | after | after / before |")
        print("|---|---|---|---|---|---|")
        gains = []
        for key in new[0]:
            b = med([r[key][1] / r[key][2] for r in old if key in r])
            a = med([r[key][1] / r[key][2] for r in new if key in r])
            gains.append(a / b)
            print(f"| {key[0]} | {key[1]} | {key[2]} | {b:.2f} | {a:.2f} | {a / b:.2f} |")
        print(f"\nMedian of after / before over the {len(gains)} pairs: {med(gains):.2f}")


if __name__ == "__main__":
    main(sys.argv[1:])
