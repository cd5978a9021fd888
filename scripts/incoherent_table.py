#!/usr/bin/env python3
"""The incoherent-rays table (issue 52) from `raytrail bench --json` files.

    scripts/incoherent_table.py [--json] RUN.json [RUN.json ...]

Each file is one run of one ray order (the `--order` of its command; morton when absent). Camera
and shadow rays are taken from the morton runs, whose order they do not depend on beyond the
camera's; diffuse and ambient-occlusion rays from every order. Per scene, view, ray set and
order: the fastest fixed raytrail CPU method of each run, the medians over the runs of its
Mrays/s, of Embree's at its default and at its high build quality, the median of the per-run
ratios of the fastest to the faster Embree of that run (not a ratio of medians), and the median
of the per-run ratios of `auto` to the fastest fixed method. With --json, the table as the
{"columns", "rows", "after"} of a docs/results/*.json table instead of Markdown.
"""
import json
import re
import statistics
import sys

FIXED_KINDS = ("raytrail-bvh2", "raytrail-kd", "raytrail-wide", "raytrail-stream")
ORDERED_RAYS = ("diffuse", "ao")
TARGET, MEDIAN_TARGET, AUTO_TOLERANCE = 1.0, 1.2, 0.9


def order_of(command):
    m = re.search(r"--order[ =](\w+)", command)
    return m.group(1) if m else "morton"


def pairs(path):
    """(scene, view, rays, order) -> (fastest name, its Mrays/s, embree, embree-high, auto)."""
    with open(path) as f:
        doc = json.load(f)
    order = order_of(doc["command"])
    out = {}
    for scene in doc["scenes"]:
        for rays in scene["rays"]:
            if order != "morton" and rays["type"] not in ORDERED_RAYS:
                continue
            rows = rays["rows"]
            fixed = [r for r in rows if r["kind"] in FIXED_KINDS and r["mrays_per_s"]]
            peer = {r["target"]: r["mrays_per_s"] for r in rows}
            if not fixed or not peer.get("embree") or not peer.get("embree-high"):
                continue
            best = max(fixed, key=lambda r: r["mrays_per_s"])
            key = (scene["name"], scene["view"], rays["type"], order)
            out[key] = (best["target"], best["mrays_per_s"], peer["embree"], peer["embree-high"], peer.get("auto"))
    return out


COLUMNS = ["scene", "view", "rays", "order", "fastest raytrail (per run)", "fastest, Mrays/s", "embree",
           "embree-high", "fastest / faster Embree", "auto / fastest"]


def table(runs):
    """The rows (lists of cells) and the summary lines of the table."""
    keys = []
    for r in runs:
        keys += [k for k in r if k not in keys]
    med = statistics.median
    rows, ratios, autos = [], [], []
    for key in keys:
        got = [r[key] for r in runs if key in r]
        names = [g[0] for g in got]
        top = max(set(names), key=names.count)
        to_embree = [g[1] / max(g[2], g[3]) for g in got]
        e = med(to_embree)
        ratios.append(e)
        auto = [g[4] / g[1] for g in got if g[4]]
        a = med(auto) if auto else None
        if a is not None:
            autos.append(a)
        rows.append([key[0], key[1], key[2], key[3], ", ".join(names), f"{top} {med([g[1] for g in got]):.2f}",
                     f"{med([g[2] for g in got]):.2f}", f"{med([g[3] for g in got]):.2f}",
                     f"{e:.2f} ({min(to_embree):.2f}-{max(to_embree):.2f}){' ✓' if e >= TARGET else ''}",
                     f"{a:.2f}{' ✓' if a >= AUTO_TOLERANCE else ''}" if a is not None else "-"])
    after = [f"{len(ratios)} pairs: median fastest / faster Embree {med(ratios):.2f} (target {MEDIAN_TARGET}), "
             f"lowest {min(ratios):.2f}; at or above {TARGET}x: {sum(e >= TARGET for e in ratios)} of {len(ratios)}"]
    if autos:
        after.append(f"auto within {1 - AUTO_TOLERANCE:.0%} of the fastest fixed method: "
                     f"{sum(a >= AUTO_TOLERANCE for a in autos)} of {len(autos)} (lowest {min(autos):.2f})")
    return rows, after


def main(argv):
    as_json = "--json" in argv
    argv = [a for a in argv if a != "--json"]
    if not argv or argv[0].startswith("-"):
        sys.exit(__doc__)
    rows, after = table([pairs(p) for p in argv])
    if as_json:
        print(json.dumps({"columns": COLUMNS, "rows": rows, "after": after}, indent=2, ensure_ascii=False))
        return
    print("| " + " | ".join(COLUMNS) + " |")
    print("|" + "---|" * len(COLUMNS))
    for r in rows:
        print("| " + " | ".join(r) + " |")
    print()
    for line in after:
        print(line)


if __name__ == "__main__":
    main(sys.argv[1:])
