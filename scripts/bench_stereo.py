#!/usr/bin/env python3
"""What stereo costs on the wall: the same wall and view with one eye (mono) and with both eyes
(side-by-side and full frames), at the defaults, under mpirun.

Stereo gives every tile a pair of ranks, one per eye. Each figure is the wall's own report with
--measure, in emulated time (each rank's own CPU clock: what a cluster with a core per rank would
take): the wall-wide time to C = 99%, the CPU makespan and the total CPU of every tile rank. The
verdict compares both eyes with one eye: time to C = 99% (target: at most 1.6x) and total CPU.

The picture gate: the full mode's left eye must be the mono wall seen from the left eye's head
position (a mono run with `head -S/2 0 0`, scripts/mosaic_gate.py's rule); where it is not, no
speed verdict holds. A level never reached counts as infinitely late.

    python3 scripts/bench_stereo.py [--isowall build/bin/isowall] [--data ../shared/data]
        [--out bench-out/stereo] [--runs 3] [--tile 512x384]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mosaic_gate  # noqa: E402

SEPARATION = 0.03  # of the wall's width
SUMMARY = re.compile(r"^makespan ([\d.]+) s \(CPU\), total ([\d.]+) s, balance ([\d.]+)")
EMULATED = re.compile(r"C = 90/99/100%: (\S+) / (\S+) / (\S+) s; final pixels")
TARGET_TIME = 1.6


def wall_file(folder, name, tile, stereo):
    w, h = tile
    path = os.path.join(folder, name + ".toml")
    with open(path, "w") as f:
        f.write(f"tiles = [2, 2]\ntile_size_px = [{w}, {h}]\n")
        if stereo:
            f.write(f'[stereo]\nmode = "{stereo}"\neye_separation = {SEPARATION}\n')
    return path


def run(isowall, wall, ranks, volume, out_png, script=None):
    cmd = ["mpirun", "--oversubscribe", "-np", str(ranks), "-x", "LP_NUM_THREADS=0", isowall,
           "wall", "--wall", wall, *volume, "--measure", "--out", out_png]
    if script:
        cmd += ["--script", script]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        sys.exit(f"bench_stereo: {' '.join(cmd)} failed:\n{proc.stderr[-2000:]}")
    r = {}
    for line in proc.stdout.splitlines():
        if m := SUMMARY.match(line):
            r["makespan"], r["total"], r["balance"] = map(float, m.groups())
        elif m := EMULATED.search(line):
            r["c99"] = float("inf") if m.group(2) == "never" else float(m.group(2))
    for key in ("makespan", "c99"):
        if key not in r:
            sys.exit(f"bench_stereo: no '{key}' in the output of {' '.join(cmd)}:\n"
                     f"{proc.stdout[-2000:]}")
    return r


def median(runs, key):
    return statistics.median(r[key] for r in runs)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--isowall", default=os.path.join(here, "..", "build", "bin", "isowall"))
    ap.add_argument("--data", default=os.path.join(here, "..", "..", "shared", "data"))
    ap.add_argument("--out", default="bench-out/stereo")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--tile", default="512x384", help="one tile's pixels, WxH")
    a = ap.parse_args()
    tile = tuple(int(v) for v in a.tile.split("x"))
    head = os.path.join(a.data, "vhp_ct_head.nhdr")
    if os.path.exists(head):
        volume, name = ["-v", head, "--iso", "40"], "vhp_ct_head at 40"
    else:
        print(f"bench_stereo: {head} is absent: the built-in phantom instead")
        volume, name = [], "phantom"
    os.makedirs(a.out, exist_ok=True)
    folder = tempfile.mkdtemp(prefix="stereo-", dir=a.out)
    walls = {"mono": (wall_file(folder, "mono", tile, None), 5),
             "side-by-side": (wall_file(folder, "sbs", tile, "side-by-side"), 9),
             "full": (wall_file(folder, "full", tile, "full"), 9)}
    left_script = os.path.join(folder, "left.txt")
    with open(left_script, "w") as f:
        f.write(f"head {-SEPARATION / 2} 0 0\nwait done\n")
    runs = {k: [] for k in walls}
    gates = []
    print(f"{name}, 2x2 tiles of {tile[0]}x{tile[1]}, eye separation {SEPARATION} of the wall's "
          f"width, {a.runs} runs each, the modes alternating")
    for i in range(a.runs):
        for mode, (wall, ranks) in walls.items():
            png = os.path.join(a.out, f"stereo_{mode}.png")
            runs[mode].append(run(a.isowall, wall, ranks, volume, png))
        left_png = os.path.join(a.out, "stereo_mono_left_head.png")
        run(a.isowall, walls["mono"][0], 5, volume, left_png, left_script)
        c = mosaic_gate.compare(os.path.join(a.out, "stereo_full-left.png"), left_png)
        gates.append(mosaic_gate.same_view(c))
        print(f"  run {i + 1}: full-mode left eye against the mono wall at the left eye's head: "
              f"{mosaic_gate.describe(c)}")
    print(f"\n| mode | ranks | time to C = 99% (s) | CPU makespan (s) | total CPU (s) |")
    print("|---|---|---|---|---|")
    for mode, (_, ranks) in walls.items():
        print(f"| {mode} | {ranks} | {median(runs[mode], 'c99'):.3f} | "
              f"{median(runs[mode], 'makespan'):.3f} | {median(runs[mode], 'total'):.3f} |")
    mono_c99, mono_total = median(runs["mono"], "c99"), median(runs["mono"], "total")
    picture = all(gates)
    print()
    for mode in ("side-by-side", "full"):
        t = median(runs[mode], "c99") / mono_c99
        cpu = median(runs[mode], "total") / mono_total
        holds = picture and t <= TARGET_TIME
        print(f"{mode}: both eyes / one eye: time to C = 99% {t:.2f}x (target <= {TARGET_TIME}: "
              f"{'holds' if holds else 'missed'}{'' if picture else ', the picture gate failed'}), "
              f"total CPU {cpu:.2f}x")
    print(f"wrote {a.out}/stereo_*.png")


if __name__ == "__main__":
    main()
