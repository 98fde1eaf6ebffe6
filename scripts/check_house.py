#!/usr/bin/env python3
"""House rules for the C++ sources: no function over about 80 lines, generated tables aside.
Prints every offender and exits 1 when there is one. Files are cut where their concepts part,
never to meet a count (STYLE.md), so a long file fails nothing: a file past PROMPT_FILE_LINES is
listed as a prompt to look for a seam, with its length, and the check still passes.

A function is found by brace depth: a `{` that opens at namespace or class scope after a line
holding `)` (a signature) starts one, the matching `}` ends it. Lambdas and local classes count
towards the function that holds them. Comments and string literals are stripped first."""
import re
import sys
from pathlib import Path

PROMPT_FILE_LINES = 800
MAX_FUNCTION_LINES = 80
GENERATED = {"extract/mc_tables.h"}
FOLDERS = ["core", "files", "wire", "volume", "progressive", "wall_spec", "extract", "readers",
           "store", "comm", "render", "display", "engine", "wall_protocol", "cli", "tile", "master",
           "remote", "app", "fuzz", "tests", "bench"]


def strip(text):
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'R"\((.*?)\)"', lambda m: '""' + "\n" * m.group(0).count("\n"), text, flags=re.S)
    text = re.sub(r'"(\\.|[^"\\\n])*"', '""', text)
    text = re.sub(r"'(\\.|[^'\\\n])'", "''", text)
    return text


def functions(text):
    """(name line, first line, last line) of each function body at namespace or class scope."""
    scopes = []  # per open brace: True when it is a function body
    out = []
    lines = strip(text).split("\n")
    pending = []  # recent non-empty lines since the last ; { or }
    for no, line in enumerate(lines, 1):
        for ch in line:
            if ch == "{":
                head = " ".join(pending + [line.split("{")[0]])
                in_function = any(scopes)
                is_fn = (not in_function and ")" in head
                         and not re.search(r"\b(class|struct|namespace|enum|union)\b[^()]*$", head)
                         and not re.search(r"=\s*$", head.strip()))
                scopes.append(is_fn)
                if is_fn:
                    start = no - len([p for p in pending if p.strip()])
                    out.append([head.strip()[:70], start, None])
                pending = []
            elif ch == "}":
                if scopes and scopes.pop() and not any(scopes):
                    out[-1][2] = no
                pending = []
            elif ch == ";" and not any(scopes):
                pending = []
        if line.strip() and not any(scopes):
            pending.append(line)
            pending = pending[-6:]
    return [(n, a, b) for n, a, b in out if b is not None]


def main(root):
    root = Path(root)
    bad, prompts = [], []
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*")):
            if path.suffix not in (".h", ".cpp"):
                continue
            rel = path.relative_to(root).as_posix()
            if rel in GENERATED:
                continue
            text = path.read_text()
            n = text.count("\n")
            if n > PROMPT_FILE_LINES:
                prompts.append(f"{rel}: {n} lines: is there a seam? (a prompt, not a failure)")
            for name, a, b in functions(text):
                if b - a + 1 > MAX_FUNCTION_LINES:
                    bad.append(f"{rel}:{a}: function of {b - a + 1} lines (at most about "
                               f"{MAX_FUNCTION_LINES}): {name}")
    for line in prompts + bad:
        print(line)
    print(f"house rules: {len(bad)} offender(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent))
