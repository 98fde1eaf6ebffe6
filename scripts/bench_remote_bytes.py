#!/usr/bin/python3
"""Bytes to C = 99% and seconds to C = 90% for a new isovalue with `isowall view` (front view,
800x600, no cache) in three settings: `compact-zstd` without LOD (the default before cells),
`cells` and `auto` (the default since: the server picks cells or compact-zstd per group for the
link it sees), both with the default progressive LOD (the server sends coarse passes where it
forecasts that they bring C = 90% sooner, remote/lod_choice.h), on every shared volume at its
README isovalues.

Usage: scripts/bench_remote_bytes.py [--isowall build/bin/isowall] [--data ../shared/data]
                                     [--rate-mbps R] [--only NAME] [--pin] [--runs N]

One `isowall serve` on loopback holds every volume; each (volume, isovalue, encoding) is one
`isowall view` run. Times are the client's wall clock (server and client share this machine's
cores, or with --pin the server on CPU 0 and the client on CPU 1, as on two machines with a core
each), bytes are what the protocol counted; with --runs N each is the median of N runs, taken in
turn (every encoding once, then again), so a disturbance of the machine falls on all three.
Prints a Markdown table with a verdict per row against the targets: bytes to C = 99% of
cells at most 1/4 of compact-zstd's, and auto's seconds to C = 90% against compact-zstd's.
Errors are one line on stderr and exit status 1; the server is always stopped.
"""
import argparse
import os
import re
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROG = "bench_remote_bytes.py"
# The README's suggested isovalues (../shared/data/README.md).
CASES = [("vhp_ct_head", 40), ("vhp_ct_head", 105), ("cthead", 600), ("cthead", 1650),
         ("mrhead_t1", 112), ("mrhead_t1", 490), ("engine", 75), ("engine", 190),
         ("heptane", 50), ("heptane", 200), ("tooth", 620), ("tooth", 1000)]
ENCODINGS = ["compact-zstd", "cells", "auto"]
# The options besides --encoding: compact-zstd stands for the default before cells.
EXTRA = {"compact-zstd": ["--no-lod"], "cells": [], "auto": []}
PORT = 7981


def fail(msg):
    print(f"{PROG}: error: {msg}", file=sys.stderr)
    sys.exit(1)


def pinned(cpu, args):
    return ["taskset", "-c", str(cpu)] + args if cpu is not None else args


def start_server(isowall, data, names, rate, cpu):
    args = [isowall, "serve", "--listen", f"127.0.0.1:{PORT}"]
    for n in names:
        args += ["--dataset", f"{n}={os.path.join(data, n + '.nhdr')}"]
    if rate:
        args += ["--rate-mbps", str(rate)]
    proc = subprocess.Popen(pinned(cpu, args), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)
    deadline = time.time() + 300
    for line in proc.stdout:
        if "listening on" in line:
            return proc
        if time.time() > deadline:
            break
    proc.kill()
    fail("isowall serve did not start listening")


def stop_server(server):
    """Stops `isowall serve` as a user would (SIGINT), killing it if it does not end in 20 s."""
    server.send_signal(signal.SIGINT)
    try:
        server.wait(timeout=20)
    except subprocess.TimeoutExpired:
        server.kill()


def view(isowall, name, iso, encoding, cpu):
    out = subprocess.run(
        pinned(cpu, [isowall, "view", "--connect", f"127.0.0.1:{PORT}", "--dataset", name,
                     "--iso", str(iso), "--encoding", encoding] + EXTRA[encoding] + [
                     "--out", f"/tmp/{PROG}-{name}-{iso}-{encoding}.png"]),
        capture_output=True, text=True, timeout=600)
    if out.returncode != 0:
        fail(f"isowall view {name} {iso} {encoding}: {out.stderr.strip()[-300:]}")
    found = {}
    for m in re.finditer(r"C >=\s+([\d.]+)%:\s+([\d.]+) s\s+(\d+) bytes", out.stdout):
        found[float(m.group(1))] = (float(m.group(2)), int(m.group(3)))
    tri = re.search(r"(\d+) triangles drawn", out.stdout)
    coarse = "coarse passes:" in out.stdout
    groups = re.search(r"(\d+) groups \((\d+) as cells\)", out.stdout)
    if 90.0 not in found or 99.0 not in found or not tri or not groups:
        fail(f"isowall view {name} {iso} {encoding}: no C figures in: {out.stdout[-300:]}")
    return found, int(tri.group(1)), (int(groups.group(2)), int(groups.group(1))), coarse


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--isowall", default=os.path.join(ROOT, "build", "bin", "isowall"))
    p.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data"))
    p.add_argument("--rate-mbps", type=float, default=0)
    p.add_argument("--only", help="one volume's name")
    p.add_argument("--pin", action="store_true",
                   help="the server on CPU 0, each client on CPU 1 (taskset)")
    p.add_argument("--runs", type=int, default=1, help="runs of each, the median kept (1)")
    a = p.parse_args()
    if a.runs < 1:
        fail(f"--runs: expected at least 1, got {a.runs}")
    cases = [c for c in CASES if not a.only or c[0] == a.only]
    if not cases:
        fail(f"--only: no volume named {a.only!r}")
    names = sorted({n for n, _ in cases})
    for n in names:
        if not os.path.exists(os.path.join(a.data, n + ".nhdr")):
            fail(f"--data: {os.path.join(a.data, n + '.nhdr')} does not exist")
    server = start_server(a.isowall, a.data, names, a.rate_mbps, 0 if a.pin else None)
    rows = []
    try:
        for name, iso in cases:
            runs = {e: [] for e in ENCODINGS}
            for _ in range(a.runs):
                for e in ENCODINGS:
                    runs[e].append(view(a.isowall, name, iso, e, 1 if a.pin else None))
            # The run of median time to C = 90% stands for the encoding.
            got = {e: sorted(r, key=lambda x: x[0][90.0][0])[len(r) // 2] for e, r in runs.items()}
            rows.append((name, iso, got))
    finally:
        stop_server(server)
    rate = f"{a.rate_mbps:g} Mbit/s" if a.rate_mbps else "loopback, unpaced"
    rate += ", server on CPU 0 and client on CPU 1" if a.pin else ""
    runs = f", the median of {a.runs} runs" if a.runs > 1 else ""
    print(f"`isowall view` (front view, 800x600, new isovalue), {rate}{runs}; bytes to C = 99% "
          f"and seconds to C = 90% for each --encoding (auto is the default); compact-zstd "
          f"without LOD (the default before cells), cells and auto with the default LOD "
          f"(coarse passes where the server forecasts that they pay)\n")
    print("| volume | iso | triangles | " +
          " | ".join(f"{e} bytes | {e} s" for e in ENCODINGS) +
          " | coarse passes | auto: groups as cells | cells / compact-zstd bytes "
          "| verdict (<= 0.25) | auto / compact-zstd s |")
    print("|---|---:|---:|" + "---:|---:|" * len(ENCODINGS) + "---|---:|---:|---|---:|")
    missed = slower = 0
    for name, iso, got in rows:
        tri = got["compact-zstd"][1]
        ratio = got["cells"][0][99.0][1] / got["compact-zstd"][0][99.0][1]
        ok = ratio <= 0.25
        missed += 0 if ok else 1
        cells = " | ".join(f"{got[e][0][99.0][1]} | {got[e][0][90.0][0]:.3f}" for e in ENCODINGS)
        as_cells, groups = got["auto"][2]
        coarse = "yes" if got["auto"][3] else "no"
        compact_s = got["compact-zstd"][0][90.0][0]
        time_ratio = got["auto"][0][90.0][0] / compact_s if compact_s > 0 else float("nan")
        slower += 1 if time_ratio > 1 else 0
        print(f"| {name} | {iso} | {tri} | {cells} | {coarse} | {as_cells} of {groups} | "
              f"{ratio:.3f} | "
              f"{'holds' if ok else 'MISSED'} | {time_ratio:.2f} |")
    print(f"\n{len(rows) - missed} of {len(rows)} rows hold the 1/4 target (cells against "
          f"compact-zstd, bytes to C = 99%)")
    print(f"auto reached C = 90% no later than compact-zstd on {len(rows) - slower} of "
          f"{len(rows)} rows")


if __name__ == "__main__":
    main()
