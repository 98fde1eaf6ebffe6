#!/usr/bin/python3
"""The load-balance study of the screen-region scheduler: a 6x4 wall (25 ranks: a master and 24
tiles) with the surface inside 1 tile, across 2, across 4 and over all tiles, with balancing off
(every tile casts its own screen: the static wall) and on at several region sizes.

Usage: scripts/balance_study.py [--build build] [--data ../shared/data] [--out out/study]
                                [--volumes head,phantom] [--regions auto,auto:emulated,256x192,...]
                                [--repeat 1]

Every figure is derived from thread CPU time, not wall time: with 25 ranks on this machine's 2
cores the wall clock says nothing about a cluster. A rank's busy CPU is what its frame thread
spent on jobs, landing helpers' results and sending its own (llvmpipe rasterises in that thread:
LP_NUM_THREADS=0). The makespan is the largest busy CPU of any rank; efficiency is mean busy /
makespan (the master's "balance"); emulated times to wall-wide C are from each rank's own CPU
clock, as if every rank had a core of its own (isowall wall --measure). Writes study.csv,
study.md (the table the README quotes), per-rank busy bars and a summary plot, and each kept
run's mosaic, into --out; prints which of the targets hold.

With --repeat N each configuration keeps the one run whose makespan is the median (for an even
N the lower of the two middle runs), with all its fields and its mosaic: a row never mixes runs,
and every figure of a target, totals included, is that run's. A balanced row's speed verdicts
hold only where its mosaic is the static row's picture (scripts/mosaic_gate.py, the rule of the
wall's mosaic tests); where it is not, each of them is missed. The targets are judged at the
default regions ("auto": planned from the work, what `isowall wall` gives without
--region); the best
region of each case, chosen after the fact, is printed for information with no verdict.
"auto:emulated" is the default regions with jobs handed out in emulated-time order (--dispatch
emulated); the script prints how far the two orders differ.
"""
import argparse
import csv
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import mosaic_gate  # noqa: E402
WALL = os.path.join(ROOT, "walls", "6x4.toml")
DEFAULT_REGION = "auto"  # `isowall wall --region`'s default: the regions users get
TILE_RANKS = 24

# (name, zoom, pan dx, pan dy): the volume's screen box inside one tile (column 2, row 1), on
# the edge between two tiles of row 1, on the corner of four, and the front full view.
CASES = [
    ("1 tile", 0.2, 0.0833, -0.125),
    ("2 tiles", 0.2, 0.0, -0.125),
    ("4 tiles", 0.3, 0.0, 0.0),
    ("all tiles", 1.0, 0.0, 0.0),
]

RANK_ROW = re.compile(
    r"^\s+(\d+)\s+(\S+)\s+(\d+)\s+([\d.]+)\s+([\d.]+)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)"
    r"\s+([\d.]+)\s+(\d+)\s+(\d+)\s+([\d.]+)$")
SUMMARY = re.compile(r"^makespan ([\d.]+) s \(CPU\), total ([\d.]+) s, balance ([\d.]+)")
EVERY = re.compile(r"^every thread .*: makespan ([\d.]+) s, total ([\d.]+) s; communication "
                   r"([\d.]+) s, at most (\d+)% of a rank's busy CPU")
SCHED = re.compile(r"^scheduler: .*: (\d+) jobs, (\d+) migrated, ([\d.]+) MB")
EMULATED = re.compile(r"C = 90/99/100%: (\S+) / (\S+) / (\S+) s; final pixels 90/99/100%: "
                      r"(\S+) / (\S+) / (\S+) s")


def volume_args(name, data):
    if name == "phantom":
        return []
    return ["-v", os.path.join(data, "vhp_ct_head.nhdr"), "--iso", "40"]


def run_wall(isowall, vol, case, balance, region, out_png, emulate_cores=0):
    _, zoom, dx, dy = case
    cmd = ["mpirun", "--oversubscribe", "-np", "25", "-x", "LP_NUM_THREADS=0", isowall, "wall",
           "--wall", WALL, *vol, "--zoom", str(zoom), "--pan", str(dx), str(dy), "--measure",
           "--balance", "on" if balance else "off", "--out", out_png,
           "--emulate-cores", str(emulate_cores)]
    if region:
        # "auto:emulated": the default regions, jobs handed out in emulated-time order
        # (--dispatch emulated) instead of on arrival.
        name, _, dispatch = region.partition(":")
        cmd += ["--region", name] + (["--dispatch", dispatch] if dispatch else [])
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        sys.exit(f"balance_study: {' '.join(cmd)} failed:\n{proc.stderr[-2000:]}")
    r = parse(proc.stdout, " ".join(cmd))
    r["png"] = out_png
    return r


def picture_cell(r):
    if r["region"] == "static":
        return "-"
    return "yes" if r["same_picture"] else "NO"


def keep_mosaic(kept, runs, png):
    """The kept run's mosaic becomes `png`; the other runs' are removed."""
    for r in runs:
        if r["png"] != kept["png"]:
            os.remove(r["png"])
    os.replace(kept["png"], png)
    kept["png"] = png


def judge_picture(row, static):
    """Whether a balanced row's mosaic is the static row's picture (scripts/mosaic_gate.py)."""
    c = mosaic_gate.compare(row["png"], static["png"])
    row["same_picture"] = mosaic_gate.same_view(c)
    row["picture"] = mosaic_gate.describe(c)


def parse(text, cmd):
    r = {"busy": [], "rays": [], "helped": [], "jobs": []}
    for line in text.splitlines():
        if m := RANK_ROW.match(line):
            r["busy"].append(float(m.group(4)))
            r["rays"].append(int(m.group(8)))
            r["jobs"].append(int(m.group(12)))
            r["helped"].append(int(m.group(13)))
        elif m := SUMMARY.match(line):
            r["makespan"], r["total"], r["balance"] = map(float, m.groups())
        elif m := EVERY.match(line):
            r["all_makespan"], r["all_total"], r["comm"] = map(float, m.groups()[:3])
            r["comm_pct"] = int(m.group(4))
        elif m := SCHED.match(line):
            r["job_count"], r["migrated"] = int(m.group(1)), int(m.group(2))
            r["mb_moved"] = float(m.group(3))
        elif m := EMULATED.search(line):
            # A level never reached counts as infinitely late, never as left out.
            vals = [float("inf") if v == "never" else float(v) for v in m.groups()]
            r["c90"], r["c99"], r["c100"], r["px90"], r["px99"], r["px100"] = vals
    for key in ("makespan", "job_count", "c99", "comm_pct"):
        if key not in r:
            sys.exit(f"balance_study: no '{key}' in the output of {cmd}:\n{text[-2000:]}")
    r["tiles_with_rays"] = sum(1 for n in r["rays"] if n > 0)
    # Busy CPU per ray cast, every rank's: how much dearer a ray (and the work that follows it)
    # is on the balanced wall than on the static one, where a tile works mostly alone.
    rays = sum(r["rays"])
    r["us_per_ray"] = 1e6 * r["total"] / rays if rays else float("inf")
    return r


def median_run(runs):
    """The run with the median makespan (the lower median for an even count), whole."""
    out = dict(sorted(runs, key=lambda r: r["makespan"])[(len(runs) - 1) // 2])
    out["runs"] = len(runs)
    return out


def plot(rows, out_dir, volume):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mine = [r for r in rows if r["volume"] == volume]
    regions = sorted({r["region"] for r in mine if r["region"] != "static"},
                     key=lambda s: -2e9 if s == "auto" else -1e9 if s.startswith("auto")
                     else -int(s.split("x")[0]))
    fig, axes = plt.subplots(len(CASES), 1, figsize=(11, 2.6 * len(CASES)), sharex=True)
    for ax, case in zip(axes, CASES):
        runs = [r for r in mine if r["case"] == case[0]]
        width = 0.8 / len(runs)
        for i, r in enumerate(runs):
            xs = [k + 1 + (i - (len(runs) - 1) / 2) * width for k in range(len(r["busy"]))]
            label = "static" if r["region"] == "static" else f"balanced {r['region']}"
            ax.bar(xs, r["busy"], width=width, label=label)
        ax.set_title(f"{volume}, surface in {case[0]}: busy CPU per rank")
        ax.set_ylabel("busy CPU s")
        ax.legend(fontsize=7, ncol=len(runs))
    axes[-1].set_xlabel("tile rank")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, f"busy_{volume}.png"), dpi=90)
    plt.close(fig)

    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(14, 4))
    labels = ["static"] + regions
    for case in CASES:
        by = {r["region"]: r for r in mine if r["case"] == case[0]}
        a1.plot(labels, [by[l]["makespan"] for l in labels], marker="o", label=case[0])
        a2.plot(labels, [by[l]["balance"] for l in labels], marker="o", label=case[0])
        a3.plot(labels, [by[l]["c99"] for l in labels], marker="o", label=case[0])
    a1.set_title("makespan (CPU s)")
    a2.set_title("efficiency (mean busy / makespan)")
    a3.set_title("emulated time to wall-wide C = 99% (s)")
    for a in (a1, a2, a3):
        a.set_xlabel("region size (static: one job per tile)")
        a.legend(fontsize=7)
    a1.set_yscale("log")
    a3.set_yscale("log")
    fig.suptitle(f"6x4 wall, {volume}: balancing off vs on")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, f"summary_{volume}.png"), dpi=90)
    plt.close(fig)


def target_figures(case, static, bal):
    """(figure, value, target, holds) for each of the targets in a case; [] if none. Every
    figure is from the two rows' own runs; a balanced mosaic that is not the static one's
    picture holds no target."""
    same = bal.get("same_picture", False)
    cpu = bal["total"] / static["total"]
    cpu_target = ("total CPU balanced/static", f"{cpu:.2f}", "<= 1.3", cpu <= 1.3)
    comm_target = ("communication, the largest share of a working rank's busy CPU",
                   f"{bal['comm_pct']}%", "<= 10%", bal["comm_pct"] <= 10)
    if case == "1 tile":
        ms = static["makespan"] / bal["makespan"]
        # The efficiency: the static wall's work over the balanced wall's ranks x makespan.
        eff = static["total"] / (TILE_RANKS * bal["makespan"])
        verdicts = [("makespan static/balanced", f"{ms:.1f}x", ">= 12x", ms >= 12),
                    ("efficiency static total/(ranks x makespan)", f"{eff:.2f}", ">= 0.75",
                     eff >= 0.75), cpu_target, comm_target]
    elif case == "all tiles":
        rel = bal["makespan"] / static["makespan"]
        verdicts = [("balance mean/max", f"{bal['balance']:.2f}", ">= 0.9",
                     bal["balance"] >= 0.9),
                    ("makespan balanced/static", f"{rel:.2f}", "<= 0.45", rel <= 0.45),
                    cpu_target, comm_target]
    else:
        return []
    return [(what, got, target, ok and same) for what, got, target, ok in verdicts]


def figures(static, r):
    return (f"makespan {r['makespan']:.3f} s (static {static['makespan']:.3f} s), efficiency "
            f"{r['balance']:.2f}, emulated C=99% {r['c99']:.3f} s (static {static['c99']:.3f} s)")


def judge_case(case, static, judged, best):
    verdicts = target_figures(case, static, judged) if judged else []
    if judged is None:
        print(f"  {case}: no verdict: the default region {DEFAULT_REGION} is not among --regions")
    elif not judged.get("same_picture", False):
        print(f"  {case}, {DEFAULT_REGION}: the balanced mosaic is not the static one's picture "
              f"({judged.get('picture', 'not compared')}): every target of the case is missed")
    if judged is not None and not verdicts:
        print(f"  {case}, {DEFAULT_REGION}: no target (the issue sets targets for 1 tile and all "
              f"tiles only); {figures(static, judged)}")
    for what, got, target, ok in verdicts:
        print(f"  {case}, {DEFAULT_REGION}: {what} {got} (target {target}): "
              f"{'holds' if ok else 'MISSED'}")
    if best is not None:
        print(f"  {case}, best region {best['region']} (chosen after the fact), for information, "
              f"no verdict: {figures(static, best)}")


def check_targets(rows, volume):
    mine = {(r["case"], r["region"]): r for r in rows if r["volume"] == volume}
    runs = sorted({r["runs"] for r in mine.values()})
    print(f"\ntargets ({volume}; each figure from the median run of {'/'.join(map(str, runs))} "
          f"by makespan; judged at the default region size {DEFAULT_REGION}):")
    for case, *_ in CASES:
        balanced = [r for (c, region), r in mine.items() if c == case and region != "static"]
        best = min(balanced, key=lambda r: r["makespan"], default=None)
        judge_case(case, mine[(case, "static")], mine.get((case, DEFAULT_REGION)), best)


def compare_dispatch(rows, volume):
    """How far the two dispatch orders differ at the default regions."""
    mine = {(r["case"], r["region"]): r for r in rows if r["volume"] == volume}
    if not any(region == "auto:emulated" for _, region in mine):
        return
    print(f"\ndispatch orders ({volume}, regions auto): on arrival against emulated-time order")
    for case, *_ in CASES:
        a, e = mine.get((case, "auto")), mine.get((case, "auto:emulated"))
        if a and e:
            print(f"  {case}: makespan {a['makespan']:.3f} / {e['makespan']:.3f} s "
                  f"({e['makespan'] / a['makespan']:.2f}x), efficiency {a['balance']:.2f} / "
                  f"{e['balance']:.2f}, C=99% {a['c99']:.3f} / {e['c99']:.3f} s, total CPU "
                  f"{a['total']:.3f} / {e['total']:.3f} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "study"))
    ap.add_argument("--volumes", default="head,phantom")
    ap.add_argument("--regions", default="auto,auto:emulated,256x192,128x96,64x48")
    ap.add_argument("--emulate-cores", type=int, default=0,
                    help="isowall wall --emulate-cores for every run (0: no limit)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="runs per configuration (the run with the median makespan is kept)")
    a = ap.parse_args()
    if a.repeat < 1:
        sys.exit(f"balance_study: --repeat: expected 1 or more runs, got {a.repeat}")
    isowall = os.path.join(a.build, "bin", "isowall")
    if not os.access(isowall, os.X_OK):
        sys.exit(f"balance_study: {isowall} not found; build first (scripts/setup.sh)")
    volumes = a.volumes.split(",")
    if "head" in volumes and not os.path.exists(os.path.join(a.data, "vhp_ct_head.nhdr")):
        print(f"balance_study: {a.data}/vhp_ct_head.nhdr not found; the head is skipped")
        volumes.remove("head")
    os.makedirs(a.out, exist_ok=True)
    print(f"each row: the median run of {a.repeat} by makespan, every field from that run")
    rows = []
    for volume in volumes:
        vol = volume_args(volume, a.data)
        for case in CASES:
            for region in ["static"] + a.regions.split(","):
                tag = f"{volume}_{case[0].replace(' ', '')}_{region}"
                png = os.path.join(a.out, f"mosaic_{tag}.png")
                runs = [run_wall(isowall, vol, case, region != "static",
                                 None if region == "static" else region,
                                 os.path.join(a.out, f"mosaic_{tag}.run{i}.png"),
                                 a.emulate_cores)
                        for i in range(a.repeat)]
                r = median_run(runs)
                keep_mosaic(r, runs, png)
                r.update(volume=volume, case=case[0], region=region)
                if region == "static":
                    static = r
                else:
                    judge_picture(r, static)
                rows.append(r)
                print(f"{volume:8s} {case[0]:10s} {region:8s} makespan {r['makespan']:.3f} s, "
                      f"total {r['total']:.3f} s, efficiency {r['balance']:.2f}, "
                      f"C=90/99/100% at {r['c90']:.3f}/{r['c99']:.3f}/{r['c100']:.3f} s, "
                      f"{r['migrated']} of {r['job_count']} jobs migrated, "
                      f"{r['mb_moved']:.1f} MB moved, tiles with rays of their own "
                      f"{r['tiles_with_rays']}; every thread: makespan {r['all_makespan']:.3f} s, "
                      f"communication {r['comm']:.3f} s, at most {r['comm_pct']}% of a rank's "
                      f"busy CPU; busy CPU per ray {r['us_per_ray']:.2f} us"
                      + (f" ({r['us_per_ray'] / static['us_per_ray']:.2f}x static's)"
                         if region != "static" else "")
                      + (f"; against static: {r['picture']}" if "picture" in r else ""),
                      flush=True)
        plot(rows, a.out, volume)
    fields = ["volume", "case", "region", "runs", "makespan", "total", "balance", "c90", "c99",
              "c100", "px90", "px99", "px100", "job_count", "migrated", "mb_moved",
              "tiles_with_rays", "all_makespan", "all_total", "comm", "comm_pct", "us_per_ray",
              "same_picture"]
    with open(os.path.join(a.out, "study.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(a.out, "study.md"), "w") as f:
        f.write(f"Each row: the median run of {a.repeat} by makespan, every field from that "
                "run.\n\n")
        f.write("| volume | surface in | regions | makespan s | total s | efficiency | "
                "C=90% s | C=99% s | C=100% s | migrated / jobs | MB moved | every-thread "
                "makespan s | comm s (largest % of busy) | static's picture |\n")
        f.write("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write(f"| {r['volume']} | {r['case']} | {r['region']} | {r['makespan']:.3f} | "
                    f"{r['total']:.3f} | {r['balance']:.2f} | {r['c90']:.3f} | {r['c99']:.3f} | "
                    f"{r['c100']:.3f} | {r['migrated']} / {r['job_count']} | "
                    f"{r['mb_moved']:.1f} | {r['all_makespan']:.3f} | {r['comm']:.3f} "
                    f"({r['comm_pct']}%) | {picture_cell(r)} |\n")
    for volume in volumes:
        check_targets(rows, volume)
        compare_dispatch(rows, volume)
    print(f"\nwrote {a.out}/study.csv, study.md, busy_*.png, summary_*.png, mosaic_*.png")


if __name__ == "__main__":
    main()
