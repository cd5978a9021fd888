#!/usr/bin/env python3
"""Fails on citations that point at nothing (Python 3, standard library only).

    python3 scripts/check_citations.py

Looks at the comments of the sources (`.rs` and `.wgsl` comments, `.py` comments and docstrings,
`.sh` comments) and at whole Markdown files, outside `docs/notes/` (dated records, left as
written) and `target/`, for:

- a Markdown file (`docs/ARCHITECTURE.md`, `../README.md`, a link target) that does not exist;
  a note cited as `docs/notes/*-<topic>.md` must name exactly one `YYYY-MM-DD-<topic>.md`;
- a quoted section title after a Markdown file (`<file>.md, "Title"`) that starts no heading of that
  file, or that does not close on its line (a citation stays on one line);
- a repository path (`core/src/wide/tree.rs`, `scripts/`, a glob such as `docs/accuracy-*.json`)
  that matches nothing.

A relative path is looked up from the citing file's folder and each folder above it up to the
repository's root (a crate's README names `src/lib.rs`). Paths through `shared/` are outside the
repository and are not checked. Prints one line per problem, `FILE:LINE: what`, and exits 1 if
there is any.
"""
import glob
import io
import os
import re
import subprocess
import sys
import tokenize

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def markdown_headings(path):
    """The heading titles of the Markdown file `path` (relative to the repository), outside code
    fences, in order."""
    out, fenced = [], False
    with open(os.path.join(ROOT, path), encoding="utf-8") as f:
        for line in f:
            if line.startswith("```"):
                fenced = not fenced
            elif not fenced and line.startswith("#"):
                out.append(line.lstrip("#").strip())
    return out
SKIP_PREFIXES = ("docs/notes/",)
NOTES_INDEX = "docs/notes/README.md"  # the index is checked; the dated notes are not
EXTENSIONS = {".rs": "slash", ".wgsl": "slash", ".py": "python", ".sh": "hash", ".md": "markdown"}
NOTE_STAR = re.compile(r"^(.*/)?\*-([\w.-]+\.md)$")
URL = re.compile(r"\b[a-z][a-z0-9+.-]*://[^\s)>\]`\"']+")
MD_TOKEN = re.compile(r"(?<![\w./*-])((?:\.\.?/)*(?:[\w*.-]+/)*[\w*.-]*[\w*-]\.md)(?![\w-])")
TITLE_AFTER = re.compile(r"^[`)\]]*(?:#[\w-]*\))?,?\s+(?:(?:the\s+)?section\s+)?\"")
PATH_TOKEN = re.compile(r"(?<![\w./$*<-])((?:\.\.?/)*[\w.-]+/(?:[\w.*-]+/)*(?:[\w.*-]*[\w*])?/?)")
LINK_TARGET = re.compile(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def files():
    try:
        out = subprocess.run(
            ["git", "ls-files", "-co", "--exclude-standard"], cwd=ROOT, capture_output=True, text=True, check=True
        ).stdout.split("\n")
    except (OSError, subprocess.CalledProcessError):
        out = []
        for d, dirs, names in os.walk(ROOT):
            dirs[:] = [x for x in dirs if x not in (".git", "target")]
            out += [os.path.relpath(os.path.join(d, n), ROOT) for n in names]
    return sorted(f for f in set(out) if f and os.path.isfile(os.path.join(ROOT, f)))


def kind_of(path):
    return EXTENSIONS.get(os.path.splitext(path)[1])


def outside_strings(line, start):
    """Whether position `start` of a line of code lies outside string literals (a rough rule)."""
    quotes, i, escaped = None, 0, False
    while i < start:
        c = line[i]
        if escaped:
            escaped = False
        elif c == "\\":
            escaped = True
        elif quotes:
            if c == quotes:
                quotes = None
        elif c in "\"'":
            quotes = c
        i += 1
    return quotes is None


def comment_lines(text, kind):
    """(line number, text) of what counts as prose in a file: comments, docstrings, or all of it."""
    lines = text.split("\n")
    if kind == "markdown":
        return list(enumerate(lines, 1))
    out = []
    if kind == "python":
        try:
            for tok in tokenize.generate_tokens(io.StringIO(text).readline):
                if tok.type == tokenize.COMMENT:
                    out.append((tok.start[0], tok.string))
                elif tok.type == tokenize.STRING and tok.string.lstrip("rbuRBU").startswith(('"""', "'''")):
                    for k, part in enumerate(tok.string.split("\n")):
                        out.append((tok.start[0] + k, part))
            return out
        except (tokenize.TokenError, SyntaxError, IndentationError):
            kind = "hash"
    marker = "//" if kind == "slash" else "#"
    for n, line in enumerate(lines, 1):
        at = line.find(marker)
        while at != -1:
            if kind == "hash" and (line.startswith("#!") or (at > 0 and not line[at - 1].isspace())):
                at = line.find(marker, at + 1)
                continue
            if kind == "slash" and at > 0 and line[at - 1] == ":":
                at = line.find(marker, at + 2)
                continue
            if outside_strings(line, at):
                out.append((n, line[at:]))
                break
            at = line.find(marker, at + 1)
    return out


class Repo:
    def __init__(self, paths):
        self.top = {p.split("/")[0] for p in paths if "/" in p} - {"target"}
        self.names = {}
        for p in paths:
            self.names.setdefault(os.path.basename(p), []).append(p)
        self.headings = {}

    def candidates(self, citing, rel):
        """Where a relative path may point: from the citing file's folder up to the root."""
        d = os.path.dirname(citing)
        seen = []
        while True:
            seen.append(os.path.normpath(os.path.join(d, rel)))
            if not d:
                break
            d = os.path.dirname(d)
        return [p for p in seen if not p.startswith("..")]

    def resolve(self, citing, rel):
        """The repository file or folder `rel` names from `citing`, or None."""
        m = NOTE_STAR.match(rel)
        for cand in self.candidates(citing, rel):
            full = os.path.join(ROOT, cand)
            if m:
                folder = os.path.dirname(full)
                name = re.compile(r"\d{4}-\d{2}-\d{2}-" + re.escape(m.group(2)) + "$")
                try:
                    hits = [f for f in os.listdir(folder) if name.match(f)]
                except OSError:
                    hits = []
                if len(hits) == 1:
                    return os.path.relpath(os.path.join(folder, hits[0]), ROOT)
                if hits:
                    return None
            elif any(c in cand for c in "*?["):
                if glob.glob(full):
                    return cand
            elif os.path.exists(full):
                return cand
        if "/" not in rel and len(self.names.get(rel, [])) == 1:
            return self.names[rel][0]  # a bare name names a file of the repository's
        return None

    def heading_list(self, path):
        if path not in self.headings:
            try:
                self.headings[path] = markdown_headings(path)
            except (OSError, UnicodeDecodeError):
                self.headings[path] = []
        return self.headings[path]

    def has_heading(self, path, title):
        t = title.strip().lower()
        bare = t.replace("`", "")
        return any(h.lower().startswith(t) or h.lower().replace("`", "").startswith(bare) for h in self.heading_list(path))


def outside(rel):
    """Paths this check leaves alone: outside the repository (`shared/`), or build outputs."""
    parts = [p for p in rel.split("/") if p not in ("", ".", "..")]
    return not parts or parts[0] == "shared" or "target" in parts


def check_file(repo, path, problems):
    kind = kind_of(path)
    if kind is None:
        return
    try:
        with open(os.path.join(ROOT, path), encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError):
        return
    fenced = False
    for n, line in comment_lines(text, kind):
        if kind == "markdown" and line.startswith("```"):
            fenced = not fenced
        line = URL.sub(lambda m: " " * len(m.group(0)), line)
        where = f"{path}:{n}"
        # Markdown files, and the section titles quoted after them.
        for m in MD_TOKEN.finditer(line):
            rel = m.group(1)
            if outside(rel):
                continue
            target = repo.resolve(path, rel)
            if target is None:
                problems.append(f"{where}: {rel}: no such file")
                continue
            rest = line[m.end():]
            q = TITLE_AFTER.match(rest)
            if not q:
                continue
            close = rest.find('"', q.end())
            if close == -1:
                problems.append(f"{where}: {rel}: the quoted title does not close on this line")
                continue
            title = rest[q.end():close]
            if not repo.has_heading(target, title):
                problems.append(f'{where}: {rel}: no heading starts with "{title}"')
        # Link targets in Markdown.
        if kind == "markdown" and not fenced:
            for m in LINK_TARGET.finditer(line):
                rel = m.group(1).split("#")[0]
                if not rel or ":" in rel or outside(rel) or rel.endswith(".md"):
                    continue
                if repo.resolve(path, rel) is None:
                    problems.append(f"{where}: {rel}: no such file")
        # Repository paths.
        for m in PATH_TOKEN.finditer(line):
            rel = m.group(1).rstrip(".")
            if rel.endswith(".md") or outside(rel):
                continue
            relative = rel.startswith(("./", "../"))
            first = [p for p in rel.split("/") if p not in (".", "..")][0]
            if not relative and first not in repo.top:
                continue
            last = rel.rstrip("/").split("/")[-1]
            code_span = line[m.start() - 1 : m.start()] == "`" and line[m.end() : m.end() + 1] == "`"
            if "." not in last and not rel.endswith("/") and not code_span:
                continue  # a folder named without a slash or backticks may be prose ("build/test")
            if repo.resolve(path, rel) is None:
                problems.append(f"{where}: {rel}: no such file or folder")


def main():
    paths = files()
    repo = Repo(paths)
    problems = []
    for path in paths:
        if (path.startswith(SKIP_PREFIXES) and path != NOTES_INDEX) or "/target/" in f"/{path}":
            continue
        check_file(repo, path, problems)
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
