#!/usr/bin/python3
"""Time to C = 90/99/99.9% (share of final pixels) of two builds of isowall, alternating runs in one
process so that both see the same machine load: the check that a refactoring kept the engine's
speed. Prints the median and minimum of each build and the ratio of medians.

Usage: scripts/bench_compare_builds.py BEFORE_BUILD AFTER_BUILD [--volume PATH] [--isos 40,105]
                                       [--size 1600x1200] [--runs 7]
A build is a folder holding bin/isowall (e.g. build/), or master/isowall (a build in the older
folder layout).
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
THRESHOLDS = (0.90, 0.99, 0.999)


def times_to_thresholds(isowall, volume, iso, size, tmp):
    timeline = os.path.join(tmp, "timeline.csv")
    cmd = [isowall, "render", "--iso", str(iso), "--size", size, "-q", "--timeline", timeline,
           "--out", os.path.join(tmp, "frame.png")]
    if volume != "phantom":
        cmd[2:2] = ["-v", volume]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"bench_compare_builds: {' '.join(cmd)} failed:\n{proc.stderr}")
    with open(timeline) as f:
        rows = list(csv.DictReader(f))
    return [next((float(r["time_s"]) for r in rows if float(r["final_pixels"]) >= th), float("nan"))
            for th in THRESHOLDS]


def program_in(build):
    """bin/isowall of a build, or master/isowall of one in the older folder layout."""
    for sub in ("bin", "master"):
        path = os.path.join(build, sub, "isowall")
        if os.access(path, os.X_OK):
            return path
    return os.path.join(build, "bin", "isowall")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--volume", default=os.path.join(os.path.dirname(ROOT), "shared", "data", "vhp_ct_head.nhdr"))
    ap.add_argument("--isos", default="40,105")
    ap.add_argument("--size", default="1600x1200")
    ap.add_argument("--runs", type=int, default=7)
    a = ap.parse_args()
    builds = {"before": program_in(a.before), "after": program_in(a.after)}
    for name, path in builds.items():
        if not os.access(path, os.X_OK):
            sys.exit(f"bench_compare_builds: {name}: {path} is not an executable")
    if a.volume != "phantom" and not os.path.exists(a.volume):
        sys.exit(f"bench_compare_builds: --volume: {a.volume} does not exist")
    isos = [float(v) for v in a.isos.split(",")]
    got = {(name, iso): [] for name in builds for iso in isos}
    with tempfile.TemporaryDirectory(prefix="isowall-compare-") as tmp:
        for run in range(a.runs):
            for name, path in builds.items():
                for iso in isos:
                    got[(name, iso)].append(times_to_thresholds(path, a.volume, iso, a.size, tmp))
            print(f"run {run + 1}/{a.runs} done", file=sys.stderr)
    print(f"{os.path.basename(a.volume)} at {a.size}, {a.runs} alternating runs per build; seconds to C")
    print(f"{'iso':>6} {'C':>6} {'before median':>14} {'(min)':>7} {'after median':>13} {'(min)':>7} {'after/before':>13}")
    for iso in isos:
        for k, th in enumerate(THRESHOLDS):
            b = [r[k] for r in got[("before", iso)]]
            f = [r[k] for r in got[("after", iso)]]
            mb, ma = statistics.median(b), statistics.median(f)
            print(f"{iso:>6g} {th * 100:>5g}% {mb:>14.3f} {min(b):>7.3f} {ma:>13.3f} {min(f):>7.3f} {ma / mb:>13.3f}")


if __name__ == "__main__":
    main()
