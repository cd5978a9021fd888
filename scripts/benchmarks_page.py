#!/usr/bin/env python3
"""Writes BENCHMARKS.md from the results in docs/results/*.json (Python 3, standard library only).

    python3 scripts/benchmarks_page.py          # rewrite BENCHMARKS.md
    python3 scripts/benchmarks_page.py --check  # exit 1 if BENCHMARKS.md is not what this writes
    python3 scripts/benchmarks_page.py --stdout # print the page

Each JSON file is one section of the page: {"order", "title", "about"?, "tables": [...]}. A table
names its caption, machine, commit, command and source ({"note": "docs/notes/*-<topic>.md",
"section": a prefix of a heading in that note}), then either "columns" and "rows" (cells are
strings, or a source object rendered as a link) or "accuracy_files" (`raytrail accuracy --json`
files, summed up per ray set). Every note and section named must exist: the page is not written
otherwise.
"""
import glob
import json
import os
import re
import sys

from check_citations import markdown_headings  # the same heading rule as the citation check

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = "docs/results"
PAGE = "BENCHMARKS.md"


# Methods renamed since results were recorded (old name, current name): table cells show the
# current name, commands keep the one they ran with (the CLI still parses it for one release).
# The same pairs as WideMethod::OLD_NAMES (core/src/method/wide.rs); a core test holds them equal.
RENAMED = [("bvh8-sah-stream", "bvh8-sah-lists"), ("bvh8-stream", "bvh8-lists")]


def current_names(text):
    for old, new in RENAMED:
        text = re.sub(r"(?<![\w-])" + re.escape(old) + r"(?![\w-])", new, text)
    return text


class SourceError(Exception):
    pass


def resolve_note(star):
    """The file a note citation `docs/notes/*-<topic>.md` names (the `*` stands for the date)."""
    folder, _, name = star.rpartition("/")
    pattern = re.compile(r"\d{4}-\d{2}-\d{2}" + re.escape(name[1:]) + "$")
    try:
        matches = sorted(f for f in os.listdir(os.path.join(ROOT, folder)) if pattern.match(f))
    except OSError:
        matches = []
    if not name.startswith("*-") or len(matches) != 1:
        raise SourceError(f"{star}: names {len(matches)} files, not one")
    return f"{folder}/{matches[0]}"


def source_link(src):
    path = resolve_note(src["note"])
    section = src["section"]
    if not any(h.lower().startswith(section.lower()) for h in markdown_headings(path)):
        raise SourceError(f'{src["note"]}: no heading starts with "{section}"')
    return f'[`{src["note"]}`]({path}), "{section}"'


def commit_text(commit):
    return re.sub(r"\b([0-9a-f]{7,40})\b", r"`\1`", commit)


def cell(value, table_source=None):
    """A table cell; a source object is a link, or only its section where it is the table's note."""
    if isinstance(value, dict):
        link = source_link(value)
        if table_source and value["note"] == table_source["note"]:
            return f'"{value["section"]}"'
        return link
    return current_names(str(value)).replace("|", "\\|")


def table(columns, rows, source=None):
    out = ["| " + " | ".join(cell(c) for c in columns) + " |", "|" + "---|" * len(columns)]
    for row in rows:
        if len(row) != len(columns):
            raise SourceError(f"a row of {len(row)} cells under {len(columns)} columns: {row}")
        out.append("| " + " | ".join(cell(c, source) for c in row) + " |")
    return out


def accuracy_rows(files):
    """One row per scene, view and ray set of `raytrail accuracy --json` files."""
    rows = []
    for name in files:
        with open(os.path.join(ROOT, name), encoding="utf-8") as f:
            data = json.load(f)
        for scene in data["scenes"]:
            for rays in scene["rays"]:
                r = rays["rows"]
                errors = sum(x["false_misses"] + x["false_hits"] + x["wrong_prims"] + x["bad_t"] for x in r)
                near = sum(x["near"] for x in r)
                refused = sum(x["refused"] for x in r)
                front = ", ".join(
                    f'{x["method"]} {"WT" if x["test"] == "watertight" else "MT"} {x["mrays_per_s"]:.2f}'
                    for x in r
                    if x["pareto"]
                )
                default = [x for x in r if x["default"]]
                default_text = ", ".join(
                    f'{x["mrays_per_s"]:.2f}, '
                    f'{x["false_misses"] + x["false_hits"] + x["wrong_prims"] + x["bad_t"]}'
                    for x in default
                )

                def t_error(test):
                    sel = [x for x in r if (x["test"] == "watertight") == (test == "watertight")]
                    return f'{max(x["t_ulps_max"] for x in sel):.2f} / {max(x["t_ulps_mean"] for x in sel):.2f}'

                rows.append([
                    scene["name"],
                    rays["kind"],
                    f'{rays["rays"]} / {rays["sampled"]}',
                    f"{errors} (near {near}, refused {refused}) of {len(r)} rows",
                    front,
                    default_text,
                    t_error("watertight"),
                    t_error("moller-trumbore"),
                ])
    return rows


ACCURACY_COLUMNS = [
    "scene (view)",
    "rays",
    "traced / judged",
    "errors",
    "Pareto front (Mrays/s)",
    "default hash, watertight (Mrays/s, errors)",
    "t error in ulps, largest max / mean: watertight",
    "Möller-Trumbore",
]


def render():
    sections = []
    for path in sorted(glob.glob(os.path.join(ROOT, RESULTS, "*.json"))):
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
        data["_file"] = os.path.relpath(path, ROOT)
        sections.append(data)
    sections.sort(key=lambda s: (s["order"], s["_file"]))
    out = [
        "# Benchmarks",
        "",
        f"This page is generated by `scripts/benchmarks_page.py` from the JSON files in `{RESULTS}/`: edit those,"
        " then run the script (`--check` says whether this page is current).",
        "",
        "The latest measured results, each table with the command, the machine and the commit it came",
        "from, and the note it was transcribed from. The notes in [docs/notes/](docs/notes/README.md) hold",
        "every measurement in the order it was made, with what was tried and not kept.",
        "",
        "Methods renamed since a table was recorded appear under their current names; its command keeps the"
        " name it ran with, which still parses: "
        + ", ".join(f"`{old}` is now `{new}`" for old, new in RENAMED)
        + ".",
        "",
    ]
    out += [f"- [{s['title']}](#{anchor(s['title'])})" for s in sections]
    for s in sections:
        out += ["", f"## {s['title']}", ""]
        if s.get("about"):
            out += s["about"] + [""]
        out.append(f"From `{s['_file']}`.")
        for t in s["tables"]:
            out += ["", f"### {t['caption']}", ""]
            out.append(f"Machine: {t['machine']}.  ")
            out.append(f"Commit: {commit_text(t['commit'])}.  ")
            out.append(f"Source: {source_link(t['source'])}.")
            if t.get("about"):
                out += [""] + t["about"]
            out += ["", "```bash", t["command"], "```", ""]
            if "accuracy_files" in t:
                out += table(ACCURACY_COLUMNS, accuracy_rows(t["accuracy_files"]))
            else:
                out += table(t["columns"], t["rows"], t["source"])
            if t.get("after"):
                out += [""] + t["after"]
    return "\n".join(out) + "\n"


def anchor(title):
    """GitHub's anchor for a heading."""
    a = re.sub(r"[^\w\- ]", "", title.strip().lower())
    return a.replace(" ", "-")


def main(argv):
    try:
        page = render()
    except (SourceError, KeyError, OSError, ValueError) as e:
        print(f"benchmarks_page.py: {e}", file=sys.stderr)
        return 2
    target = os.path.join(ROOT, PAGE)
    if "--stdout" in argv:
        sys.stdout.write(page)
        return 0
    if "--check" in argv:
        try:
            with open(target, encoding="utf-8") as f:
                current = f.read()
        except OSError:
            current = ""
        if current != page:
            old, new = current.split("\n"), page.split("\n")
            line = next((i for i, (a, b) in enumerate(zip(old, new)) if a != b), min(len(old), len(new)))
            print(
                f"{PAGE} differs from what scripts/benchmarks_page.py writes (first at line {line + 1}); "
                "run python3 scripts/benchmarks_page.py",
                file=sys.stderr,
            )
            return 1
        return 0
    with open(target, "w", encoding="utf-8") as f:
        f.write(page)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
