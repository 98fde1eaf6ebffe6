#!/usr/bin/python3
"""Scaling benchmark: time to C = 90/99/99.9/100% of final pixels of the progressive
engine (`isowall render --timeline`), our full surface (`isowall render --full`: extraction plus
drawing) and the FE + Embree peer (VTK flying edges on 2 threads, then an Embree 3 BVH and 8-wide
primary rays: scripts/fe_mesh.py and bench/peer's isowall-peer), for one volume at several
scales, all in one run, with the issue's targets marked holds or MISSED.

Usage: /usr/bin/python3 scripts/bench_scaling.py [--scales 1,2] [--size 1600x1200] [--iso 40]
           [--runs 3] [--pair-rounds 2] [--volume vhp_ct_head] [--build build] [--data ../shared/data]
           [--out out/bench-scaling] [--threads 2] [--engines defaults,full-res,...] [--cold]
       /usr/bin/python3 scripts/bench_scaling.py --rerender OLD/scaling.json [--out DIR]
           (an older run's JSON judged by today's statistic and verdicts; writes scaling-rerendered.md)

Scale 1 is the volume itself; any other scale is a trilinear copy made once by
scripts/resample_volume.py into BUILD/data and kept there (outside git). For the shared CT head:
scale 2 is 1024x1024x468 (491 M voxels, 491 MB, 3 minutes to make on a loaded 2-core machine);
scale 4 is 2048x2048x936 (3.9 G voxels, 3.9 GB of disk, 12 minutes to make there; each program
holds the 3.9 GB of voxels and a run peaked at 8.4 GB in one process; 4-5 minutes per run). Scales 1,2 take about two
minutes once the copy is made.

Every program measures its steady state by default: `isowall render --warm-up` draws one untimed
frame of the view turned 30 degrees before the timed one (`--full` extracts and draws the surface
once first), and the peer runs flying edges, the BVH build and the rays twice in its processes and
times the second run. A wall's ranks draw frame after frame, so this is what a viewer waits for
after moving the camera. --cold times every program's first run in a fresh process instead (the
memory it touches then is new to it: page faults, the renderer's first buffers and bins). isowall
keeps freed memory for the next frame (core/util.h: keep_freed_memory); the peer's processes
run with the same C library settings (MALLOC_TRIM_THRESHOLD_, MALLOC_MMAP_THRESHOLD_).

Two threads against one: the targets compare the defaults on one thread (full-res) and on every
core (defaults). After the --runs rounds of every engine, --pair-rounds more rounds run only
those two (in turn one first, then the other), each followed by a one-pass machine check; their
runs stay out of the medians below and count only in the two-thread verdict, the median over
every round of that round's own speed-up. A table gives every round's speed-ups beside the
machine's. Beside them the run prints, for each scale, the peer's own 2-thread gain (flying
edges, BVH and rays on 1 thread, one run) and what the machine's two cores gave two threads of
plain work at that time (bench/cores' isowall-cores: arithmetic, and random reads over 256 MiB;
2.0 is perfect), since on a shared machine that moves from hour to hour.

Each progressive configuration (--engines; the first, by default `defaults`, is the one the
targets judge) also prints its final image against the full surface (`render --against-full`)
and against the truth (`render --against-truth`: the full surface at 4x4 samples a pixel,
box-filtered), outside the clock. A verdict on a speed holds only when the judged final image
passes the fidelity gate of the same runs (C_T within 0.005 and coverage IoU within 0.002 of the
full surface at one sample a pixel, or better; saved runs without the truth are judged by C >=
0.99 and coverage IoU >= 0.999): a fast engine that draws another picture does not pass, and a
run that never reaches a threshold counts as missed. Every figure is wall-clock seconds measured inside the programs (loading and the
octree are outside them). Every contender (each engine, --full, FE + Embree) runs --runs times
and keeps its median run (by time to C = 99%, extract + draw, and FE + BVH + rays; all runs are
in the JSON; a missed run ranks last), the engines' runs taking turns round by round. The peer's mesh goes from Python to C++ through a file in a temp folder,
outside the clock. Writes OUT/scaling.md, OUT/scaling.json and OUT/scaling.png (time against voxels,
log-log). Errors: one line naming the option, exit 1.
"""
import argparse
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from resample_volume import InputError, read_header  # noqa: E402
from bench_scaling_report import PAIR, plot, report, targets  # noqa: E402

THRESHOLDS = [("c90", 0.90), ("c99", 0.99), ("c999", 0.999), ("c100", 1.0)]

# The progressive engine's configurations (`isowall render` options). "lod": adaptive resolution
# whose level follows the projected size (meta-cells up to 2.5 px, so triangles stay about a
# pixel as the volume grows), without refinement; "facing": the visible-surface rule; "-2t": on
# two threads (every other configuration on one); "-mapped": the volume read from its shared memory
# map instead of the copy in huge pages that `--huge-pages auto` makes from 256 MiB up (not run by
# default; they show what the copy gains, in the same run).
ENGINES = {
    "defaults": [],  # `isowall render` without an engine option: what users get, what targets judge
    "full-res": ["--threads", "1"],  # the defaults on one thread
    "facing": ["--threads", "1", "--facing-only"],
    "lod": ["--threads", "1", "--adaptive", "--adaptive-pixels", "2.5", "--no-adaptive-refine"],
    "lod-refine": ["--threads", "1", "--adaptive", "--adaptive-pixels", "2.5"],
    "lod-facing": ["--threads", "1", "--adaptive", "--adaptive-pixels", "2.5", "--no-adaptive-refine",
                   "--facing-only"],
    "lod-facing-2t": ["--threads", "2", "--adaptive", "--adaptive-pixels", "2.5", "--no-adaptive-refine",
                      "--facing-only"],
}
ENGINES["lod-facing-mapped"] = ENGINES["lod-facing"] + ["--huge-pages", "off"]
ENGINES["lod-facing-2t-mapped"] = ENGINES["lod-facing-2t"] + ["--huge-pages", "off"]


class BenchError(Exception):
    pass


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, status 1 (argparse's own is usage + status 2)
        raise BenchError(message)


def positive_list(option, text, limit):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if not values or any(not (0 < v <= limit) for v in values) or len(set(values)) != len(values):
        raise BenchError(f"{option}: expected distinct comma-separated factors in (0, {limit:g}], got {text!r}")
    return sorted(values)


def parse_args(argv):
    ap = Parser(description=__doc__.split("\n\n")[0], epilog=__doc__.split("\n\n", 1)[1],
                formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scales", default="1,2", help="factors per axis (default %(default)s; 4 is the 2048-wide head)")
    ap.add_argument("--size", default="1600x1200", help="screen WIDTHxHEIGHT (default %(default)s)")
    ap.add_argument("--iso", type=float, default=40.0, help="isovalue (default %(default)s: skin of the head)")
    ap.add_argument("--runs", type=int, default=3,
                    help="runs of each measure of every contender, the median kept (default %(default)s)")
    ap.add_argument("--pair-rounds", type=int, default=2,
                    help="more rounds of full-res and defaults only (the two-thread target), each with a "
                    "machine check (default %(default)s)")
    ap.add_argument("--volume", default="vhp_ct_head", help="a name in --data or an .nhdr file (default %(default)s)")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="build folder (default: build)")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"),
                    help="shared data folder (default: ../shared/data)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench-scaling"), help="output folder")
    ap.add_argument("--threads", type=int, default=2, help="the peer's threads (default %(default)s)")
    ap.add_argument("--engines", default="defaults,full-res,lod-facing-2t,lod-facing,facing,lod,lod-refine",
                    help="progressive configurations, comma-separated, of " + ", ".join(ENGINES) +
                    "; the first is the one the targets judge (default %(default)s)")
    ap.add_argument("--cold", action="store_true",
                    help="time each program's first run in a fresh process (default: the run after a warm-up)")
    a = ap.parse_args(argv)
    a.warm = [] if a.cold else ["--warm-up"]
    a.repeat = "1" if a.cold else "2"
    a.engines = [e for e in a.engines.split(",") if e]
    bad = [e for e in a.engines if e not in ENGINES]
    if not a.engines or bad or len(set(a.engines)) != len(a.engines):
        raise BenchError(f"--engines: expected distinct names of {', '.join(ENGINES)}, got {','.join(a.engines)!r}")
    a.scales = positive_list("--scales", a.scales, 8)
    m = re.fullmatch(r"(\d{1,5})x(\d{1,5})", a.size)
    if not m or min(int(m.group(1)), int(m.group(2))) < 1:
        raise BenchError(f"--size: expected WIDTHxHEIGHT of positive integers, got {a.size!r}")
    a.width, a.height = int(m.group(1)), int(m.group(2))
    if not math.isfinite(a.iso):
        raise BenchError(f"--iso: expected a finite number, got {a.iso}")
    if not 1 <= a.runs <= 20:
        raise BenchError(f"--runs: expected an integer in [1, 20], got {a.runs}")
    if not 0 <= a.pair_rounds <= 20:
        raise BenchError(f"--pair-rounds: expected an integer in [0, 20], got {a.pair_rounds}")
    if not 1 <= a.threads <= 64:
        raise BenchError(f"--threads: expected an integer in [1, 64], got {a.threads}")
    a.isowall = os.path.join(a.build, "bin", "isowall")
    a.peer = os.path.join(a.build, "bench", "peer", "isowall-peer")
    a.cores = os.path.join(a.build, "bench", "cores", "isowall-cores")
    for program in (a.isowall, a.cores):
        if not os.path.exists(program):
            raise BenchError(f"--build: {program} not found; build first (bash scripts/setup.sh)")
    if os.sep in a.volume or a.volume.endswith(".nhdr"):
        a.source = a.volume
        if not os.path.exists(a.source):
            raise BenchError(f"--volume: {a.source} not found")
    else:
        a.source = os.path.join(a.data, a.volume + ".nhdr")
        if not os.path.exists(a.source):
            raise BenchError(f"--data: {a.source} not found (is ../shared/data there? or give --volume FILE)")
    return a


def run(cmd, what, env=None):
    """stdout of `cmd`; a failure is one BenchError line naming `what` and the last stderr line."""
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=3600, env=env)
    except subprocess.TimeoutExpired:
        raise BenchError(f"{what}: no answer within an hour: {' '.join(cmd)}")
    if proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise BenchError(f"{what}: exit {proc.returncode}: {last}")
    return proc.stdout


def key_values(text):
    return {k: float(v) for k, v in (line.split(" ", 1) for line in text.splitlines() if " " in line)}


def scaled_volume(a, scale):
    """The volume at `scale`: the source itself, or its resampled copy in BUILD/data (made once)."""
    sizes, dtype, _, _ = read_header(a.source)
    if scale == 1:
        return a.source, sizes
    out_sizes = [max(2, int(round(s * scale))) for s in sizes]
    base = os.path.splitext(os.path.basename(a.source))[0]
    name = "{}_{}x{}x{}".format(base, *out_sizes)
    path = os.path.join(a.build, "data", name + ".nhdr")
    if not os.path.exists(path):
        gb = out_sizes[0] * out_sizes[1] * out_sizes[2] * dtype.itemsize / 1e9
        print(f"scale {scale:g}: making {path} once ({gb:.2f} GB of disk)", flush=True)
        t0 = time.monotonic()
        run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "resample_volume.py"), a.source,
             "--scale", f"{scale:g}", "--out-dir", os.path.join(a.build, "data"), "--name", name],
            f"--scales {scale:g}: resample_volume.py")
        print(f"scale {scale:g}: made in {time.monotonic() - t0:.0f} s", flush=True)
    return path, out_sizes


def truth_figures(out, what):
    """The final image and the full surface at one sample a pixel against the truth (`render
    --against-truth`): {"ct": C_T, "iou_t": IoU, "full_ct", "full_iou_t", "gate": bool}."""
    res = {}
    for key, label in (("", "final image:"), ("full_", "full surface at 1 sample a pixel:")):
        m = re.search(r"^  " + re.escape(label) + r"\s+C_T = ([\d.]+), coverage IoU ([\d.]+)", out, re.M)
        if not m:
            raise BenchError(f"{what}: no '{label}' line against the truth in its output")
        res[key + "ct"], res[key + "iou_t"] = float(m.group(1)), float(m.group(2))
    m = re.search(r"^  fidelity gate: (holds|FAILS)", out, re.M)
    if not m:
        raise BenchError(f"{what}: no fidelity gate line in its output")
    res["gate"] = m.group(1) == "holds"
    return res


def first_reaching(rows, th):
    return next((r for r in rows if r["final_pixels"] >= th), None)


def progressive(a, volume, tmp, engine):
    csv_path = os.path.join(tmp, "timeline.csv")
    out = run([a.isowall, "render", "-v", volume, "--iso", f"{a.iso:g}", "--size", a.size, "-q",
               "--out", os.path.join(tmp, "progressive.png"), "--timeline", csv_path, "--against-full",
               "--against-truth", *ENGINES[engine], *a.warm], f"isowall render --timeline ({engine})")
    with open(csv_path) as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    res = {}
    for key, th in THRESHOLDS:
        hit = first_reaching(rows, th)
        res[key] = hit["time_s"] if hit else None
    hit99 = first_reaching(rows, 0.99)
    res["triangles_c99"] = int(hit99["triangles"]) if hit99 else None
    res["every_ray_s"] = rows[-1]["time_s"]
    res["triangles"] = int(rows[-1]["triangles"])
    res["covered_px"] = int(re.search(r"^covered: the final image covers (\d+) px$", out, re.M).group(1))
    m = re.search(r"^against the full surface .*: C = ([\d.]+), final px ([\d.]+)%, coverage IoU ([\d.]+)",
                  out, re.M)
    res["c_vs_full"], res["final_px_vs_full"] = float(m.group(1)), float(m.group(2)) / 100
    res["iou_vs_full"] = float(m.group(3))
    res.update(truth_figures(out, f"isowall render ({engine})"))
    res["engine"] = engine
    return res


def full(a, volume, tmp):
    out = run([a.isowall, "render", "-v", volume, "--iso", f"{a.iso:g}", "--size", a.size, "--full",
               "--out", os.path.join(tmp, "full.png"), *a.warm], "isowall render --full")
    ext = float(re.search(r"^extract: .*\(([\d.]+) s\)$", out, re.M).group(1))
    m = re.search(r"^render: .*, (\d+) px \(([\d.]+) s\)$", out, re.M)
    tris = int(re.search(r"^extract: iso \S+: (\d+) triangles", out, re.M).group(1))
    return {"extract_s": ext, "draw_s": float(m.group(2)), "full_s": ext + float(m.group(2)),
            "triangles": tris, "covered_px": int(m.group(1))}


def peer_missing(a):
    """Why the peer cannot run here, or None."""
    if not os.path.exists(a.peer):
        return f"{a.peer} not built (needs libembree-dev)"
    if subprocess.run(["/usr/bin/python3", "-c", "import vtk"], capture_output=True).returncode != 0:
        return "python3-vtk9 not installed"
    return None


# isowall keeps freed memory for the next frame (core/util.h: keep_freed_memory); the
# peer's processes get the same C library settings through its environment.
PEER_ENV = dict(os.environ, MALLOC_TRIM_THRESHOLD_=str(1 << 30), MALLOC_MMAP_THRESHOLD_=str(32 << 20))


def peer(a, volume, tmp, threads=None):
    threads = str(threads or a.threads)
    mesh = os.path.join(tmp, "peer.mesh")
    fe = key_values(run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "fe_mesh.py"), volume,
                         f"{a.iso:g}", mesh, "--threads", threads, "--repeat", a.repeat], "fe_mesh.py", PEER_ENV))
    rays = key_values(run([a.peer, mesh, "--size", a.size, "--threads", threads, "--repeat", a.repeat],
                          "isowall-peer", PEER_ENV))
    os.remove(mesh)
    return {"fe_s": fe["fe_s"], "bvh_s": rays["bvh_s"], "rays_s": rays["rays_s"],
            "total_s": fe["fe_s"] + rays["bvh_s"] + rays["rays_s"],
            "first_total_s": fe["fe_first_s"] + rays["bvh_first_s"] + rays["rays_first_s"],
            "triangles": int(fe["triangles"]), "hit_px": int(rays["hit_pixels"])}


def median_run(runs, key):
    """The run whose `key` is the median of every run (the lower middle one for an even count),
    whole, with every run beside it: every contender gets the same statistic. A run that never
    reached `key` counts as infinitely slow: it stays in the ranking, never dropped."""
    ranked = sorted(runs, key=lambda r: math.inf if r.get(key) is None else r[key])
    return dict(ranked[(len(ranked) - 1) // 2], runs=runs)


def pair_rounds(a, volume, tmp, runs):
    """--pair-rounds more rounds of the two engines the two-thread target compares (one thread
    first in even rounds, two threads first in odd ones, so a slow stretch of the machine does not
    always fall on the same one), each followed by what the machine's cores gave two threads then.
    Their runs stay out of the engines' medians (every contender has --runs runs); returns every
    round in which both ran, the first --runs rounds included, with its speed-ups."""
    pair = [e for e in PAIR if e in a.engines]
    if len(pair) < 2:
        return []
    machine = [None] * a.runs
    extra = {e: [] for e in pair}
    for k in range(a.pair_rounds):
        for e in (pair if k % 2 == 0 else pair[::-1]):
            extra[e].append(progressive(a, volume, tmp, e))
        machine.append(key_values(run([a.cores, "--reps", "1"], "isowall-cores")))
    rounds = []
    for i, (one, two) in enumerate(zip(runs[pair[0]] + extra[pair[0]], runs[pair[1]] + extra[pair[1]])):
        def gain(key):
            return one[key] / two[key] if one.get(key) and two.get(key) else None
        rounds.append({"round": i + 1, "c99_speedup": gain("c99"), "every_ray_speedup": gain("every_ray_s"),
                       "machine": machine[i]})
    return rounds


def measure_scale(a, scale, skip_peer, tmp):
    volume, sizes = scaled_volume(a, scale)
    run([a.isowall, "info", "-v", volume], "isowall info")  # builds the octree cache, untimed
    res = {"scale": scale, "volume": volume, "sizes": sizes, "voxels": sizes[0] * sizes[1] * sizes[2]}
    # Runs of the engines take turns (a round of every engine, then the next round), so the
    # median of each comes from the same stretch of time on a shared machine: a two-thread
    # figure and its one-thread baseline then see the same other tenants.
    runs = {e: [] for e in a.engines}
    for _ in range(a.runs):
        for e in a.engines:
            runs[e].append(progressive(a, volume, tmp, e))
    res["pair_rounds"] = pair_rounds(a, volume, tmp, runs)
    res["engines"] = {e: median_run(runs[e], "c99") for e in a.engines}
    res["progressive"] = res["engines"][a.engines[0]]  # the one the targets judge
    res["full"] = median_run([full(a, volume, tmp) for _ in range(a.runs)], "full_s")
    if skip_peer:
        res["peer"] = {"skipped": skip_peer}
    else:
        res["peer"] = median_run([peer(a, volume, tmp) for _ in range(a.runs)], "total_s")
        # The peer on one thread (one run): how much its two threads gain on this machine.
        if a.threads == 2:
            res["peer_1t"] = peer(a, volume, tmp, 1)
    # What the machine's two cores gave two threads around this scale's runs (bench/cores).
    res["cores"] = key_values(run([a.cores, "--reps", "3"], "isowall-cores"))
    return res


def rerender(path, out):
    """An older scaling.json judged by today's rules: each contender's median of its first --runs
    runs (older runs kept the fastest, and the pair engines had more runs than the others)."""
    try:
        with open(path) as f:
            old = json.load(f)
        meta, results = old["meta"], old["scales"]
    except (OSError, ValueError, KeyError) as e:
        raise BenchError(f"--rerender: {path}: not a scaling.json ({e})")
    n = meta["runs"]
    for r in results:
        r["engines"] = {e: median_run(v.get("runs", [v])[:n], "c99") for e, v in r["engines"].items()}
        r["progressive"] = r["engines"][next(iter(meta["engines"]))]
        r["full"] = median_run(r["full"].get("runs", [r["full"]])[:n], "full_s")
        if "total_s" in r["peer"]:
            r["peer"] = median_run(r["peer"].get("runs", [r["peer"]])[:n], "total_s")
    meta.setdefault("pair", ["lod-facing", "lod-facing-2t"])  # the pair of the runs before
    meta["statistic"] = "median, re-rendered"
    text = report(meta, results, targets(results, meta["pair"]))
    print(text)
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "scaling-rerendered.md"), "w") as f:
        f.write(text)
    return 0


def main(argv):
    if "--rerender" in argv:
        ap = Parser(description="an older scaling.json judged by today's rules")
        ap.add_argument("--rerender", required=True)
        ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench-scaling"))
        ap.add_argument("--build")  # accepted and unused: no program runs
        r = ap.parse_args(argv)
        return rerender(r.rerender, r.out)
    a = parse_args(argv)
    skip_peer = peer_missing(a)
    if skip_peer:
        print(f"peer: skipped: {skip_peer}")
    os.makedirs(a.out, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="isowall-scaling-")
    results = []
    try:
        for scale in a.scales:
            t0 = time.monotonic()
            results.append(measure_scale(a, scale, skip_peer, tmp))
            print(f"scale {scale:g}: measured in {time.monotonic() - t0:.0f} s", flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    checks = targets(results, PAIR)
    meta = {"volume": a.source, "iso": a.iso, "size": a.size, "runs": a.runs, "pair_rounds": a.pair_rounds,
            "threads": a.threads, "statistic": "median", "pair": list(PAIR),
            "frame": "cold" if a.cold else "warm",
            "engines": {e: " ".join(ENGINES[e]) or "(defaults)" for e in a.engines},
            "date": time.strftime("%Y-%m-%d %H:%M"), "cores": os.cpu_count(),
            "load_average": [round(x, 2) for x in os.getloadavg()]}
    text = report(meta, results, checks)
    print(text)
    with open(os.path.join(a.out, "scaling.md"), "w") as f:
        f.write(text)
    with open(os.path.join(a.out, "scaling.json"), "w") as f:
        json.dump({"meta": meta, "scales": results, "targets": checks}, f, indent=1)
    plot(meta, results, os.path.join(a.out, "scaling.png"))
    print(f"wrote {a.out}/scaling.md, scaling.json, scaling.png")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except (BenchError, InputError) as e:
        print(f"bench_scaling: error: {e}", file=sys.stderr)
        sys.exit(1)
