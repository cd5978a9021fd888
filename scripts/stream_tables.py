#!/usr/bin/env python3
"""Markdown tables for the notes (docs/notes/) from `raytrail bench --json` runs of the stream method.

Usage: stream_tables.py RUN.json [RUN.json ...]
With several runs (the same command repeated), each speed is the median over the runs.
Prints: the stream method beside the fastest depth-first method per scene and ray type, and the
stream stages (Garanzha & Loop's Fig. 13) with their working figures (their Table 1).
"""
import json
import statistics
import sys


def load(paths):
    runs = [json.load(open(p)) for p in paths]
    speeds, stages = {}, {}
    for run in runs:
        for scene in run["scenes"]:
            for rays in scene["rays"]:
                key = (scene["name"], rays["type"], rays["rays"])
                for row in rays["rows"]:
                    speeds.setdefault(key, {}).setdefault(row["target"], []).append(row["mrays_per_s"])
                    if row.get("stream"):
                        stages.setdefault(key, {}).setdefault(row["target"], []).append(row["stream"])
    return runs[0]["command"], speeds, stages


def main(paths):
    command, speeds, stages = load(paths)
    print(f"Command ({len(paths)} run{'s' if len(paths) > 1 else ''}): `{command.strip()}`\n")
    print("| scene | rays | fastest depth-first | Mrays/s | stream Mrays/s | stream / fastest |")
    print("|---|---|---|---:|---:|---:|")
    for (scene, kind, n), targets in speeds.items():
        med = {t: statistics.median(v) for t, v in targets.items()}
        depth_first = {t: v for t, v in med.items() if not t.startswith("stream")}
        best = max(depth_first, key=depth_first.get)
        for t in sorted(x for x in med if x.startswith("stream")):
            print(f"| {scene} | {kind} ({n:,}) | {best} | {med[best]:.2f} | {med[t]:.2f} ({t}) | {med[t] / med[best]:.2f}x |")
    print()
    print("| scene | rays | target | sort ms | frustums ms | traversal ms | intersection ms | packets | rays/packet | leaves/packet | longest list | queue sizes per level | working MB |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    for (scene, kind, n), targets in stages.items():
        for t, runs in targets.items():
            st = sorted(runs, key=lambda s: s["sort_s"] + s["frustums_s"] + s["traversal_s"] + s["intersection_s"])[len(runs) // 2]
            ms = lambda x: f"{1e3 * x:.1f}"
            print(
                f"| {scene} | {kind} | {t} | {ms(st['sort_s'])} | {ms(st['frustums_s'])} | {ms(st['traversal_s'])} | "
                f"{ms(st['intersection_s'])} | {st['packets']:,} | {n / max(st['packets'], 1):.1f} | "
                f"{st['leaf_refs'] / max(st['packets'], 1):.1f} | {st['largest_list']:,} | "
                f"{' '.join(str(q) for q in st['queue_sizes'])} | {st['working_bytes'] / 2**20:.1f} |"
            )


if __name__ == "__main__":
    main(sys.argv[1:])
