#!/usr/bin/env python3
"""What a second surface costs: `isowall render` at the defaults (warm, 1600x1200) of the shared
CT head's skin alone, its bone alone, and the skin at 0.3 opacity over the bone, in turns, each
--runs times; the median time to C = 99% of each picture's own final image, and the ratio of the
two surfaces to each one alone (target: at most 1.6x one surface).

The picture gate: the two surfaces' final picture against the full surfaces composited
(--against-full: coverage IoU >= 0.999 and C >= 0.99); where it fails, no speed verdict holds.
A run that never reaches C = 99% counts as infinitely slow.

    python3 scripts/bench_surfaces.py [--isowall build/bin/isowall] [--data ../shared/data]
        [--runs 3] [--skin 40] [--bone 105]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

C99 = re.compile(r"^\s+C=1-E >= 99%\s+(\S+)")
FULL = re.compile(r"against the full surface .*: C = ([\d.]+), .* coverage IoU ([\d.]+)")
TARGET = 1.6


def render(isowall, volume, iso_args, out, against_full):
    cmd = [isowall, "render", "-v", volume, *iso_args, "--warm-up", "-q", "--out", out]
    if against_full:
        cmd.append("--against-full")
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"bench_surfaces: {' '.join(cmd)} failed:\n{proc.stderr[-2000:]}")
    r = {"c99": float("inf")}
    for line in proc.stdout.splitlines():
        if m := C99.match(line):
            r["c99"] = float("inf") if m.group(1) == "not" else float(m.group(1))
        elif m := FULL.search(line):
            r["c"], r["iou"] = float(m.group(1)), float(m.group(2))
    return r


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--isowall", default=os.path.join(here, "..", "build", "bin", "isowall"))
    ap.add_argument("--data", default=os.path.join(here, "..", "..", "shared", "data"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--skin", default="40")
    ap.add_argument("--bone", default="105")
    a = ap.parse_args()
    volume = os.path.join(a.data, "vhp_ct_head.nhdr")
    if not os.path.exists(volume):
        sys.exit(f"bench_surfaces: {volume} is missing (../shared absent?)")
    cases = {
        "skin alone": ["--iso", a.skin],
        "bone alone": ["--iso", a.bone],
        "skin 0.3 over bone": ["--iso", f"{a.skin}:skin:0.3", "--iso", f"{a.bone}:bone"],
    }
    times = {name: [] for name in cases}
    gate = None
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "x.png")
        for k in range(a.runs):
            for name, args in cases.items():
                r = render(a.isowall, volume, args, out, against_full=(k == 0 and "over" in name))
                times[name].append(r["c99"])
                if "iou" in r:
                    gate = r
    print(f"CT head, 1600x1200, defaults, warm; median of {a.runs} runs, engines in turn")
    print("| picture | time to C = 99% (s), each run | median |")
    print("|---|---|---|")
    med = {}
    for name, t in times.items():
        med[name] = statistics.median_low(t)
        print(f"| {name} | {', '.join(f'{x:.3f}' for x in t)} | {med[name]:.3f} |")
    holds_picture = gate is not None and gate["iou"] >= 0.999 and gate["c"] >= 0.99
    print(f"picture gate (two surfaces against the full surfaces composited): C {gate['c']:.5f}, "
          f"IoU {gate['iou']:.5f}: {'holds' if holds_picture else 'FAILS'}")
    two = med["skin 0.3 over bone"]
    for one in ("skin alone", "bone alone"):
        ratio = two / med[one]
        ok = holds_picture and ratio <= TARGET
        print(f"two surfaces / {one}: {ratio:.2f} (target at most {TARGET}): "
              f"{'holds' if ok else 'MISSED'}")


if __name__ == "__main__":
    main()
