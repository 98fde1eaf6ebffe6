#!/usr/bin/env python3
"""The house's floors (docs/architecture.md): a folder includes headers only from folders on a
floor below its own. Folders on one floor are siblings and never include each other, so no folder
includes one above it and no two folders include each other. tests/, fuzz/ and bench/ stand above
every floor. Prints every offending include as FILE:LINE and exits 1 when there is one.

With --self-test, also checks that the rule catches an include upwards and one between siblings
(a check that cannot fail proves nothing)."""
import re
import sys
from pathlib import Path

# Bottom floor first. A folder not listed here and holding C++ sources is itself an offence, so
# that a new folder gets a floor when it is made.
FLOORS = [
    ["core"],
    ["files", "wire"],
    ["volume", "progressive", "wall_spec"],
    ["extract", "readers", "store"],
    ["comm", "render", "display", "engine"],
    ["wall_protocol", "cli"],
    ["tile", "master", "remote"],
    ["app"],
]
ABOVE_ALL = ["tests", "fuzz", "bench"]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
# GL, EGL and OSMesa headers: only render/'s back ends (and the render benchmark) include them,
# so that nothing else, the engine least of all, can call GL.
GL_INCLUDE = re.compile(r'^\s*#\s*include\s+[<"](GL|EGL|GLES\d*|KHR)/')
GL_ALLOWED = ["render", "tests", "bench"]


def floor_of():
    """Folder -> floor number (ABOVE_ALL: past the last floor)."""
    floors = {folder: i for i, line in enumerate(FLOORS) for folder in line}
    for folder in ABOVE_ALL:
        floors[folder] = len(FLOORS)
    return floors


def folder_of(path, floors):
    """The longest listed folder that holds `path` (a path relative to the root), or None."""
    parts = path.split("/")
    for n in range(len(parts) - 1, 0, -1):
        folder = "/".join(parts[:n])
        if folder in floors:
            return folder
    return None


def offences(files, floors):
    """(file, line number, message) of each include that breaks the rule; `files` maps a relative
    path to its text."""
    bad = []
    for rel, text in sorted(files.items()):
        here = folder_of(rel, floors)
        if here is None:
            bad.append((rel, 0, "a folder with no floor in scripts/check_layers.py"))
            continue
        for no, line in enumerate(text.split("\n"), 1):
            if GL_INCLUDE.match(line) and here not in GL_ALLOWED:
                bad.append((rel, no, f"{here}/ includes a GL header; only render/ may"))
                continue
            m = INCLUDE.match(line)
            if not m or "/" not in m.group(1):
                continue
            there = folder_of(m.group(1), floors)
            if there is None or there == here:
                continue
            if floors[there] > floors[here]:
                bad.append((rel, no, f"{here}/ includes {m.group(1)}, a floor above it"))
            elif floors[there] == floors[here] and floors[here] < len(FLOORS):
                bad.append((rel, no, f"{here}/ includes {m.group(1)} of its sibling {there}/"))
    return bad


def sources(root):
    out = {}
    top = {f.split("/")[0] for line in FLOORS for f in line} | set(ABOVE_ALL)
    for folder in sorted(top):
        for path in sorted((root / folder).rglob("*")):
            if path.suffix in (".h", ".cpp") and path.is_file():
                out[path.relative_to(root).as_posix()] = path.read_text(errors="replace")
    return out


def self_test(floors):
    up = offences({"engine/a.cpp": '#include "tile/tile_loop.h"\n'}, floors)
    # The engine hands groups to a sink and sees no renderer: render/ is its sibling.
    draws = offences({"engine/a.cpp": '#include "render/renderer.h"\n'}, floors)
    side = offences({"tile/a.cpp": '#include "master/mosaic.h"\n'}, floors)
    down = offences({"tile/a.cpp": '#include "engine/progressive_engine.h"\n#include "tile/b.h"\n'}, floors)
    stray = offences({"newfolder/a.cpp": "\n"}, floors)
    gl = offences({"engine/a.cpp": "#include <GL/gl.h>\n", "render/b.cpp": "#include <EGL/egl.h>\n"},
                  floors)
    ok = len(up) == 1 and len(side) == 1 and len(draws) == 1 and not down and len(stray) == 1
    ok = ok and len(gl) == 1
    print(f"layers self-test: up {len(up)}, sibling {len(side)}, engine to render {len(draws)}, "
          f"down {len(down)}, stray {len(stray)}, GL outside render {len(gl)}: "
          f"{'ok' if ok else 'FAILED'}")
    return ok


def main(argv):
    root = Path(__file__).resolve().parent.parent
    floors = floor_of()
    if "--self-test" in argv and not self_test(floors):
        return 1
    files = sources(root)
    bad = offences(files, floors)
    for rel, no, msg in bad:
        print(f"{rel}:{no}: {msg}")
    print(f"layers: {len(files)} sources on {len(FLOORS)} floors, {len(bad)} offence(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
