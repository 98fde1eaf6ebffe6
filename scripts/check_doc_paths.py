#!/usr/bin/python3
"""Checks the repository paths that README.md and docs/*.md name, and their table rows.

Usage: /usr/bin/python3 scripts/check_doc_paths.py   (from anywhere; the root is found from here)

A path is checked when it is named
  - inside backticks: a token holding a '/' whose first part is one of the root's entries (listed
    when the script runs; build output, out/ and .git aside), or a token that is a root entry's
    name itself (`README.md`), or a source file (.h .cpp .py .sh .mjs .cmake) under any folder, so
    that a path into a folder since renamed or removed is caught; a trailing ':LINE' or '/' is
    dropped;
  - as a markdown link or image target, `[text](target)`: resolved from the file's own folder, as
    a markdown viewer does, and a '#anchor' must name a heading of the target (or of the file).
Left alone: URLs, tokens with spaces, `$VARS`, globs and patterns (* ? { } [ ] < > |), and paths
under build*/ or out/, or starting with '/', '~' or '../' (outside the repository). A placeholder
word in a repository path (fuzz/corpus/NAME) is checked like any path: name a real one instead.

Each missing path is a line `FILE:LINE: PATH does not exist`; so is each markdown table row
longer than MAX_ROW characters (`FILE:LINE: table row of N characters (over 120)`). Exits 1 when
there is any, else prints `doc paths: N checked` and exits 0. Standard library only."""
import re
import sys
from pathlib import Path

MAX_ROW = 120
ROOT = Path(__file__).resolve().parent.parent
# Root entries that are not the repository's own content: build folders, outputs, tool state.
NOT_SOURCE = re.compile(r"^(build.*|out|scratch|node_modules|\.git)$")
BACKTICK = re.compile(r"`([^`\n]+)`")
LINK = re.compile(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
SOURCE_SUFFIXES = (".h", ".cpp", ".py", ".sh", ".mjs", ".cmake")
FENCE = re.compile(r"^\s*(```|~~~)")


def root_entries():
    return {p.name for p in ROOT.iterdir() if not NOT_SOURCE.match(p.name)}


def is_placeholder(token):
    """True for a pattern, not a path: <x>, a{b,c}, *.png, $VAR. An upper-case word inside a path
    under a repository folder (fuzz/corpus/NAME) is not a placeholder here: a reader takes it for a
    path, so the docs name a real one (fuzz/corpus/nrrd) instead."""
    return bool(re.search(r"[*?{}\[\]<>|$]", token)) or "..." in token


def backtick_path(token, entries):
    """The repository path a backticked token names, or None when it names none."""
    token = token.strip()
    if not token or " " in token or "://" in token or token.startswith(("/", "~", "../", "-")):
        return None
    token = re.sub(r":\d+(-\d+)?$", "", token)  # file.cpp:12 names file.cpp
    first = token.split("/", 1)[0]
    # A source file under a folder the root no longer has (a folder renamed or removed) is still
    # a path: checked, so that a doc naming the old place fails.
    if first not in entries and not ("/" in token and token.endswith(SOURCE_SUFFIXES)
                                     and not NOT_SOURCE.match(first)):
        return None
    if "/" not in token and token != first:
        return None
    if is_placeholder(token):
        return None
    return token.rstrip("/")


def link_path(target, doc):
    """(repository path, anchor) a link target names, or None for URLs and outside paths."""
    if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("/", "~")):
        return None
    path, _, anchor = target.partition("#")
    if not path:
        return (doc.relative_to(ROOT).as_posix(), anchor)
    resolved = (doc.parent / path).resolve()
    try:
        rel = resolved.relative_to(ROOT).as_posix()
    except ValueError:
        return None  # outside the repository
    first = rel.split("/", 1)[0]
    if NOT_SOURCE.match(first) or is_placeholder(rel):
        return None
    return (rel, anchor)


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"`", "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors_of(path, cache={}):
    if path not in cache:
        names, seen, fenced = set(), {}, False
        for line in (ROOT / path).read_text(encoding="utf-8").splitlines():
            if FENCE.match(line):
                fenced = not fenced
            m = None if fenced else re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
            if m:
                base = slug(m.group(1))
                n = seen.get(base, 0)
                seen[base] = n + 1
                names.add(base if n == 0 else f"{base}-{n}")
        cache[path] = names
    return cache[path]


def check_file(doc, entries, problems):
    """Appends each problem of one markdown file; returns how many paths it checked."""
    name = doc.relative_to(ROOT).as_posix()
    checked = 0
    fenced = False
    for no, line in enumerate(doc.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if fenced:
            continue
        if line.lstrip().startswith("|") and len(line) > MAX_ROW:
            problems.append(f"{name}:{no}: table row of {len(line)} characters (over {MAX_ROW})")
        for token in BACKTICK.findall(line):
            path = backtick_path(token, entries)
            if path is not None:
                checked += 1
                if not (ROOT / path).exists():
                    problems.append(f"{name}:{no}: {path} does not exist")
        for target in LINK.findall(BACKTICK.sub("", line)):
            named = link_path(target, doc)
            if named is None:
                continue
            path, anchor = named
            checked += 1
            if not (ROOT / path).exists():
                problems.append(f"{name}:{no}: {path} does not exist")
            elif anchor and path.endswith(".md") and anchor not in anchors_of(path):
                problems.append(f"{name}:{no}: {path}#{anchor} does not exist")
    return checked


def main():
    entries = root_entries()
    docs = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
    problems = []
    checked = sum(check_file(doc, entries, problems) for doc in docs if doc.is_file())
    for line in problems:
        print(line)
    if problems:
        return 1
    print(f"doc paths: {checked} checked")
    return 0


if __name__ == "__main__":
    sys.exit(main())
