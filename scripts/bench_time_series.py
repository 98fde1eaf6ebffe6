#!/usr/bin/env python3
"""A time series on the wall: a simulation of 8 steps (metaballs drifting through a 256^3 volume,
made once into --data-out), played on a 2x2 wall at the defaults under mpirun with --measure.

It prints, for every step, the wall-wide emulated time to C = 99% and how long after the change
every tile had cast its first ray of the step (the wall's own `time N:` lines); then how fast a
change interrupts the wall: the same wall changed mid-frame six times by `iso` and six times by
`time`, each change `--wait-rays` rays into the frame before it, the median and largest of those
switch times ("view changes:" line). Target: a step change interrupts within the bound of an
isovalue change (its largest switch at most 1.5x the isovalue's largest, or within 20 ms of it).

    python3 scripts/bench_time_series.py [--isowall build/bin/isowall] [--data-out out/bench-time]
        [--tile 512x384] [--wait-rays 3000]
"""
import argparse
import os
import re
import subprocess
import sys

import numpy as np

STEPS = 8
SIDE = 256
STEP = re.compile(r"^time (\d+): frame \d+ done in ([\d.]+) s, emulated ([\d.]+) s"
                  r"(?:, C = 99% at ([\d.]+) s)?(?:; every tile on it ([\d.]+) ms)?")
SWITCH = re.compile(r"^view changes: (\d+); .* ([\d.]+) ms after the change \(median\), "
                    r"([\d.]+) ms at most")


def make_series(folder):
    os.makedirs(folder, exist_ok=True)
    z, y, x = np.meshgrid(*(np.arange(SIDE, dtype=np.float32),) * 3, indexing="ij")
    for t in range(STEPS):
        path = os.path.join(folder, f"blobs_{t:02d}.nrrd")
        if os.path.exists(path):
            continue
        field = np.zeros((SIDE,) * 3, np.float32)
        for k in range(5):  # five blobs on circles of their own, a step = 1/8 of a turn
            a = 2 * np.pi * (t / STEPS + k / 5)
            cx, cy, cz = 128 + 60 * np.cos(a + k), 128 + 50 * np.sin(a), 128 + 40 * np.sin(a + 2 * k)
            field += 1.0 / (1e-3 + ((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / 900.0)
        data = np.clip(field * 60, 0, 255).astype(np.uint8)
        with open(path, "wb") as f:
            f.write(f"NRRD0004\ntype: uint8\ndimension: 3\nsizes: {SIDE} {SIDE} {SIDE}\n"
                    "encoding: raw\n\n".encode())
            f.write(data.tobytes())
    return os.path.join(folder, "blobs_%02d.nrrd")


def wall(isowall, wall_file, pattern, script, out_png):
    cmd = ["mpirun", "--oversubscribe", "-np", "5", "-x", "LP_NUM_THREADS=0", isowall, "wall",
           "--wall", wall_file, "-v", pattern, "--iso", "100", "--measure", "--script", script,
           "--out", out_png]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        sys.exit(f"bench_time_series: {' '.join(cmd)} failed:\n{proc.stderr[-2000:]}")
    return proc.stdout


def switches(stdout):
    for line in stdout.splitlines():
        if m := SWITCH.match(line):
            return int(m.group(1)), float(m.group(2)), float(m.group(3))
    return 0, float("inf"), float("inf")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--isowall", default=os.path.join(here, "..", "build", "bin", "isowall"))
    ap.add_argument("--data-out", default=os.path.join(here, "..", "out", "bench-time"))
    ap.add_argument("--tile", default="512x384")
    ap.add_argument("--wait-rays", type=int, default=3000)
    a = ap.parse_args()
    pattern = make_series(os.path.join(a.data_out, "series"))
    w, h = a.tile.split("x")
    wall_file = os.path.join(a.data_out, "2x2.toml")
    with open(wall_file, "w") as f:
        f.write(f"tiles = [2, 2]\ntile_size_px = [{w}, {h}]\n")

    def script(name, lines):
        path = os.path.join(a.data_out, name)
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
        return path

    out_png = os.path.join(a.data_out, "mosaic.png")
    played = wall(a.isowall, wall_file, pattern, script("play.txt", ["play", "wait done"]), out_png)
    print(f"{STEPS} steps of {SIDE}^3 played on a 2x2 wall of {a.tile} tiles, --measure "
          "(emulated: each rank on a core of its own)")
    print("| step | wall s | emulated makespan s | C = 99% (emulated) s | every tile on it, ms |")
    print("|---|---|---|---|---|")
    seen = 0
    for line in played.splitlines():
        if m := STEP.match(line):
            seen += 1
            c99 = m.group(4) or "never"
            on = m.group(5) or "-"
            print(f"| {m.group(1)} | {m.group(2)} | {m.group(3)} | {c99} | {on} |")
    if seen != STEPS:
        print(f"MISSED: {seen} of {STEPS} steps reported")
    r = a.wait_rays
    iso_lines, time_lines = [], []
    for k in range(6):
        iso_lines += [f"wait rays {r}", f"iso {90 + 4 * k}"]
        time_lines += [f"wait rays {r}", f"time {k + 1}"]
    n_iso, med_iso, max_iso = switches(
        wall(a.isowall, wall_file, pattern, script("iso.txt", iso_lines + ["wait done"]), out_png))
    n_time, med_time, max_time = switches(
        wall(a.isowall, wall_file, pattern, script("time.txt", time_lines + ["wait done"]),
             out_png))
    print("| change, mid-frame | changes | every tile on the new view: median ms | largest ms |")
    print("|---|---|---|---|")
    print(f"| iso | {n_iso} | {med_iso:.1f} | {max_iso:.1f} |")
    print(f"| time | {n_time} | {med_time:.1f} | {max_time:.1f} |")
    ok = max_time <= max(1.5 * max_iso, max_iso + 20.0)
    print(f"a step change interrupts within an isovalue change's bound: "
          f"{'holds' if ok else 'MISSED'} ({max_time:.1f} ms against {max_iso:.1f} ms)")


if __name__ == "__main__":
    main()
