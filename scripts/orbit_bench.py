#!/usr/bin/python3
"""Interaction on the wall, timed: the 6x4 wall (25 ranks) turns the view in steps (36 of 10
degrees by default) and, after each step, reports from emulated time (each rank's thread CPU
clock, as if it had a core of its own) how long the wall takes to be 90% and 99% correct
(wall-wide C), static (--balance off) against balanced (the defaults), and the views per second
that makes at C = 99%.

Usage: scripts/orbit_bench.py [--build build] [--data ../shared/data] [--out out/orbit]
                              [--volume FILE --iso V] [--steps 36] [--step-deg 10]
                              [--wall walls/6x4.toml]

Each step waits for the frame to finish ("orbit D 0", "wait done"), so every step's curve is
measured against its complete picture: a step that interrupted the last would leave no complete
picture of the interrupted view to measure against. The balanced wall's regions of each step are
planned from the last step's measured costs (master/region_plan.h), as while an operator turns
the view. Prints every step, the medians and whether the balanced median time to C = 99% is at
most 1/4 of the static one; writes orbit.csv and orbit_<volume>.png into --out.

A step that never reaches a level counts as infinitely late in the medians, never as left out.
The verdict holds only where the balanced wall's last mosaic is the static wall's picture
(scripts/mosaic_gate.py, the rule of the wall's mosaic tests): a balanced wall that is quick
because it draws something else is not quick.
"""
import argparse
import csv
import math
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import mosaic_gate  # noqa: E402

WALL = os.path.join(ROOT, "walls", "6x4.toml")
FRAME = re.compile(r"^frame (\d+): emulated C = 90/99/100%: (\S+) / (\S+) / (\S+) s$")
LAST = re.compile(r"C = 90/99/100%: (\S+) / (\S+) / (\S+) s; final pixels")


def ranks_needed(isowall, wall):
    proc = subprocess.run([isowall, "wall", "--wall", wall, "--ranks-needed"], capture_output=True,
                          text=True)
    if proc.returncode != 0 or not proc.stdout.strip().isdigit():
        sys.exit(f"orbit_bench: error: --wall: {proc.stderr.strip() or proc.stdout.strip()}")
    return proc.stdout.strip()


def seconds(text):
    """An emulated time as printed; "never" (the level was not reached) is infinitely late."""
    return float("inf") if text == "never" else float(text)


def verdict(static_c99, balanced_c99, same_picture):
    """(ratio of the medians of time to C = 99%, balanced over static; whether the target holds).
    Missed where the pictures differ or where the balanced median is never."""
    s, b = statistics.median(static_c99), statistics.median(balanced_c99)
    ratio = b / s if s > 0 and not (math.isinf(s) and math.isinf(b)) else float("inf")
    return ratio, same_picture and ratio <= 0.25


def run(isowall, wall, volume, iso, steps, step_deg, balance, out_dir):
    script = os.path.join(out_dir, "orbit_script.txt")
    with open(script, "w") as f:
        f.write("wait done\n")
        for _ in range(steps):
            f.write(f"orbit {step_deg} 0\nwait done\n")
        f.write("quit\n")
    mode = "balanced" if balance else "static"
    cmd = ["mpirun", "--oversubscribe", "-np", ranks_needed(isowall, wall), "-x",
           "LP_NUM_THREADS=0", isowall, "wall", "--wall", wall, "-v", volume, "--iso", str(iso), "--measure", "--script", script,
           "--balance", "on" if balance else "off",
           "--out", os.path.join(out_dir, f"orbit_{mode}.png")]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        sys.exit(f"orbit_bench: {' '.join(cmd)} failed:\n{proc.stderr[-2000:]}")
    frames = {}
    last = None
    for line in proc.stdout.splitlines():
        if m := FRAME.match(line):
            frames[int(m.group(1))] = (seconds(m.group(2)), seconds(m.group(3)))
        elif m := LAST.search(line):
            last = (seconds(m.group(1)), seconds(m.group(2)))
    if last is None:
        sys.exit(f"orbit_bench: no emulated-time line in the output of {' '.join(cmd)}")
    # Generation 1 is the first view; steps are 2..steps+1, the last one printed apart.
    out = [frames.get(g) for g in range(2, steps + 1)] + [last]
    missing = [g for g in range(2, steps + 1) if g not in frames]
    if missing:
        sys.exit(f"orbit_bench: {mode}: no curve for frames {missing}")
    return out


def plot(rows, path, volume, wall):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10, 4))
    steps = [r["step"] for r in rows if r["mode"] == "static"]
    for mode, colour in (("static", "tab:red"), ("balanced", "tab:blue")):
        mine = [r for r in rows if r["mode"] == mode]
        ax.plot(steps, [r["c99"] for r in mine], marker="o", color=colour, label=f"{mode} C=99%")
        ax.plot(steps, [r["c90"] for r in mine], linestyle="--", color=colour,
                label=f"{mode} C=90%")
    ax.set_xlabel("step (each turns the view; the frame runs to its end)")
    ax.set_ylabel("emulated s after the step")
    ax.set_yscale("log")
    ax.set_title(f"{wall}, {volume}: time to wall-wide correctness after each step")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line and status 1, as every bad option of isowall
        sys.exit(f"orbit_bench: error: {message}")


def main():
    ap = Parser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "orbit"))
    ap.add_argument("--volume", help="a volume file (default: the shared CT head, iso 40)")
    ap.add_argument("--iso", type=float)
    ap.add_argument("--steps", type=int, default=36)
    ap.add_argument("--step-deg", type=float, default=10)
    ap.add_argument("--wall", default=WALL)
    a = ap.parse_args()
    if a.steps < 2:
        sys.exit("orbit_bench: error: --steps: expected 2 or more")
    if not a.step_deg > 0 or a.step_deg > 180:
        sys.exit("orbit_bench: error: --step-deg: expected more than 0, at most 180")
    if (a.volume is None) != (a.iso is None):
        sys.exit("orbit_bench: error: --volume and --iso go together")
    volume = a.volume or os.path.join(a.data, "vhp_ct_head.nhdr")
    iso = a.iso if a.iso is not None else 40
    if not os.path.exists(volume):
        sys.exit(f"orbit_bench: error: --volume: no such file {volume}")
    isowall = os.path.join(a.build, "bin", "isowall")
    if not os.path.exists(isowall):
        sys.exit(f"orbit_bench: error: --build: no {isowall} (build first)")
    if not os.path.isfile(a.wall):
        sys.exit(f"orbit_bench: error: --wall: no such file {a.wall}")
    os.makedirs(a.out, exist_ok=True)
    name = os.path.basename(volume).split(".")[0]

    rows = []
    for balance in (False, True):
        mode = "balanced" if balance else "static"
        for step, (c90, c99) in enumerate(
                run(isowall, a.wall, volume, iso, a.steps, a.step_deg, balance, a.out), start=1):
            rows.append({"volume": name, "mode": mode, "step": step, "c90": c90, "c99": c99})
    with open(os.path.join(a.out, "orbit.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    plot(rows, os.path.join(a.out, f"orbit_{name}.png"), name,
         os.path.basename(a.wall).split(".")[0] + " wall")

    print(f"{name}, {a.steps} steps of {a.step_deg:g} degrees, emulated seconds after each step "
          "to wall-wide C = 90% / 99%:")
    print("  step   static C90  C99    balanced C90  C99")
    by = {(r["mode"], r["step"]): r for r in rows}
    for step in range(1, a.steps + 1):
        s, b = by[("static", step)], by[("balanced", step)]
        print(f"  {step:4d}   {s['c90']:8.3f} {s['c99']:6.3f}   {b['c90']:10.3f} {b['c99']:6.3f}")
    med = {(m, k): statistics.median(r[k] for r in rows if r["mode"] == m)
           for m in ("static", "balanced") for k in ("c90", "c99")}
    for m in ("static", "balanced"):
        print(f"{m}: median C=90% {med[(m, 'c90')]:.3f} s, C=99% {med[(m, 'c99')]:.3f} s: "
              f"{1 / med[(m, 'c99')]:.1f} views per second at C = 99%")
    picture = mosaic_gate.compare(os.path.join(a.out, "orbit_balanced.png"),
                                  os.path.join(a.out, "orbit_static.png"))
    print(f"the last view's mosaics, balanced against static: {mosaic_gate.describe(picture)}")
    ratio, holds = verdict([r["c99"] for r in rows if r["mode"] == "static"],
                           [r["c99"] for r in rows if r["mode"] == "balanced"],
                           mosaic_gate.same_view(picture))
    print(f"target: balanced median time to C = 99% at most 1/4 of static: {ratio:.2f} "
          f"({'holds' if holds else 'MISSED'})")
    print(f"wrote {os.path.join(a.out, 'orbit.csv')} and orbit_{name}.png")


if __name__ == "__main__":
    main()
