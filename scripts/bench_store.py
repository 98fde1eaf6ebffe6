#!/usr/bin/python3
"""Volumes past memory (issue 32): the same volume read from its file and from a store made by
`isowall import`, with the default `isowall render` (1600x1200, front view), on a cold page
cache (as root: `sync; echo 3 > /proc/sys/vm/drop_caches` before each run) and warm: time to the
first picture and to 99% of the final pixels, the peak resident memory, and what the store read.
The store is read once at the default memory limit and once at --limit (well under the volume).

Usage: /usr/bin/python3 scripts/bench_store.py [--volume build/data/cthead_1024x1024x452.nhdr]
           [--iso 600] [--limit 256M] [--runs 2] [--size 1600x1200] [--no-cold]
           [--build build] [--out out/bench-store]

Prints one table (markdown) and writes it to OUT/store.md. Without root, or with --no-cold, the
cold rows are skipped and say so. Errors: one line naming the option or the program, exit 1.
"""
import argparse
import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print(f"bench_store: error: {msg}", file=sys.stderr)
    sys.exit(1)


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 1)[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--volume", default=os.path.join(ROOT, "build/data/cthead_1024x1024x452.nhdr"))
    ap.add_argument("--iso", type=float, default=600.0)
    ap.add_argument("--limit", default="256M")
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--size", default="1600x1200")
    ap.add_argument("--no-cold", action="store_true", help="warm runs only (no drop_caches)")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out/bench-store"))
    try:
        a = ap.parse_args(argv)
    except SystemExit as e:
        if e.code == 0:
            raise
        sys.exit(1)
    if a.runs < 1:
        fail(f"--runs: expected at least 1, got {a.runs}")
    if not os.path.exists(a.volume):
        fail(f"--volume: {a.volume}: no such file (scripts/resample_volume.py makes the copies)")
    a.binary = os.path.join(a.build, "bin", "isowall")
    if not os.access(a.binary, os.X_OK):
        fail(f"--build: {a.binary}: not built (run scripts/setup.sh)")
    return a


def drop_caches():
    subprocess.run(["sync"], check=True)
    with open("/proc/sys/vm/drop_caches", "w") as f:
        f.write("3\n")


def number(pattern, text, default=None):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else default


def render(a, volume, extra, cold, cache_dir):
    if cold:
        drop_caches()
    png = os.path.join(a.out, "render.png")
    cmd = [a.binary, "render", "--volume", volume, "--iso", str(a.iso), "--out", png, "--size", a.size,
           "--cache-dir", cache_dir] + extra
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    if p.returncode != 0:
        fail(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()[:300]}")
    out = p.stdout
    return {
        "first": number(r"first picture: ([0-9.]+) s after the command began", out),
        "c99": number(r"final px >= 99%\s+([0-9.]+)", out),
        "frame": number(r"progressive frame ([0-9.]+) s", out),
        "rss": number(r"peak RSS ([0-9.]+) MiB", out),
        "read": number(r"bricks: \d+ read \(([0-9.]+) MiB from disk\)", out),
        "peak": number(r"peak ([0-9.]+) MiB of the", out),
        "command": wall,
    }


def median(values):
    v = sorted(x for x in values if x is not None)
    return v[len(v) // 2] if v else None


def main(argv):
    a = parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    cache_dir = os.path.join(a.out, "octree-cache")
    name = os.path.basename(a.volume).split(".")[0]
    store = os.path.join(a.out, name + ".zarr")
    t0 = time.monotonic()
    p = subprocess.run([a.binary, "import", a.volume, "--out", store, "--force", "-q",
                        "--cache-dir", cache_dir], capture_output=True, text=True)
    if p.returncode != 0:
        fail(f"import: exit {p.returncode}: {p.stderr.strip()[:300]}")
    import_s = time.monotonic() - t0
    print(p.stdout.strip())
    cold_ok = os.geteuid() == 0 and not a.no_cold
    cases = [("file", a.volume, []), ("store, default limit", store, []),
             (f"store, --memory-limit {a.limit}", store, ["--memory-limit", a.limit])]
    rows = []
    for label, volume, extra in cases:
        render(a, volume, extra, False, cache_dir)  # the octree cache, the program's own pages
        for cold in (True, False):
            if cold and not cold_ok:
                rows.append((label, "cold", None))
                continue
            runs = [render(a, volume, extra, cold, cache_dir) for _ in range(a.runs)]
            rows.append((label, "cold" if cold else "warm",
                         {k: median([r[k] for r in runs]) for k in runs[0]}))
    fmt = lambda v, f="%.3f": "-" if v is None else f % v  # noqa: E731
    lines = [f"# {name}: file against store, default render ({a.size}), iso {a.iso:g}",
             "",
             f"Import took {import_s:.1f} s. Medians of {a.runs} runs; seconds, MiB.",
             "",
             "| source | cache | first picture | 99% of final px (frame) | whole command "
             "| peak RSS | store read from disk | store peak |",
             "|---|---|---|---|---|---|---|---|"]
    for label, cache, r in rows:
        if r is None:
            why = "--no-cold" if a.no_cold else "not root (no drop_caches)"
            lines.append(f"| {label} | {cache} | skipped: {why} | | | | | |")
            continue
        lines.append(f"| {label} | {cache} | {fmt(r['first'])} | {fmt(r['c99'])} "
                     f"| {fmt(r['command'], '%.2f')} | {fmt(r['rss'], '%.0f')} "
                     f"| {fmt(r['read'], '%.1f')} | {fmt(r['peak'], '%.1f')} |")
    text = "\n".join(lines) + "\n"
    print(text)
    with open(os.path.join(a.out, "store.md"), "w") as f:
        f.write(text)
    print(f"wrote {os.path.join(a.out, 'store.md')}")


if __name__ == "__main__":
    main(sys.argv[1:])
