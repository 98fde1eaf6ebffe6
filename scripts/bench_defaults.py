#!/usr/bin/python3
"""Chooses a default of the progressive engine over every shared volume: sweeps one integer
`isowall render` option over each `*.nhdr` in ../shared/data at the isovalues its README.md
suggests, and picks the default by a stated rule.

Usage: /usr/bin/python3 scripts/bench_defaults.py [--option max-count] [--values 500,1000,2000,4000,8000]
           [--runs 3] [--size 1600x1200] [--volumes tooth,engine,...] [--build build]
           [--data ../shared/data] [--out out/bench-defaults]

The volumes are every `*.nhdr` in --data, each at the two isovalues of the README's "Suggested
isovalues" table (parsed from the README; a volume the table leaves out is skipped with a line
saying so). Each run is `isowall render -v VOL --iso ISO --size WxH --warm-up -q --timeline CSV
--out PNG --OPTION VALUE` and nothing more: the defaults are the product, so every other option
stays at its default (threads: every core). Every frame runs from a copy of BUILD/bin/isowall
taken at the start (its build time and hash are in the output), so a rebuild during the sweep
changes nothing. `isowall info` runs once per volume first, so the octree cache is built outside
the timings. From each timeline it takes the time to C = 99% (the first sample whose share of
final pixels is >= 0.99, as scripts/bench_scaling.py measures it) and the time of every ray (the
last sample).

Noise: the machine is shared, so each case (volume, isovalue) runs --runs rounds, each round every
value once, in an order rotated from round to round and case to case, so that the values of a case
share the machine's load; each cell is the median of its case's --runs runs.

The rule: in each case, a value's ratio is its median time to C = 99% over the case's best median
time to C = 99%. The default is the value with the smallest worst-case ratio over all cases; ties
go to the smaller geometric mean of its ratios, then to the smaller value. Only --option
max-count is swept: it is the one integer option the default engine (count propagation) reads.

Writes OUT/defaults.md (the table as printed) and OUT/defaults.json (every run). Without the data
folder it prints why and exits 0. Errors: one line naming the option, exit 1.
"""
import argparse
import csv
import glob
import hashlib
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_DATA = os.environ.get("ISOWALL_SHARED_DATA", os.path.join(os.path.dirname(ROOT), "shared", "data"))
# The integer options this sweep may vary, with their valid range (`isowall render --help`).
OPTIONS = {"max-count": (1, 2**31 - 1)}
RULE = ("rule: in each case a value's ratio = its median time to C = 99% / the case's best median; "
        "the default is the value with the smallest worst-case ratio over all cases "
        "(ties: the smaller geometric mean, then the smaller value)")


class BenchError(Exception):
    pass


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, status 1 (argparse's own is usage + status 2)
        raise BenchError(message)


def parse_args(argv):
    ap = Parser(description=__doc__.split("\n\n")[0], epilog=__doc__.split("\n\n", 1)[1],
                formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--option", default="max-count", help="the render option to sweep: " + ", ".join(OPTIONS)
                    + " (default %(default)s)")
    ap.add_argument("--values", default="500,1000,2000,4000,8000", help="its values (default %(default)s)")
    ap.add_argument("--runs", type=int, default=3, help="rounds; each cell is the median (default %(default)s)")
    ap.add_argument("--size", default="1600x1200", help="screen WIDTHxHEIGHT (default %(default)s)")
    ap.add_argument("--volumes", default="", help="only these volumes (names in --data, comma-separated; "
                    "default: every *.nhdr)")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="build folder (default: build)")
    ap.add_argument("--data", default=None, help="shared data folder (default: $ISOWALL_SHARED_DATA, else "
                    "../shared/data)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench-defaults"),
                    help="output folder for defaults.md and defaults.json (default: out/bench-defaults)")
    a = ap.parse_args(argv)
    if a.option not in OPTIONS:
        raise BenchError(f"--option: expected one of {', '.join(OPTIONS)}, got {a.option!r}")
    lo, hi = OPTIONS[a.option]
    try:
        a.values = [int(v) for v in a.values.split(",")]
    except ValueError:
        a.values = []
    if len(a.values) < 2 or len(set(a.values)) != len(a.values) or any(not lo <= v <= hi for v in a.values):
        raise BenchError(f"--values: expected at least two distinct comma-separated integers in [{lo}, {hi}]")
    a.values.sort()
    if not 1 <= a.runs <= 20:
        raise BenchError(f"--runs: expected an integer in [1, 20], got {a.runs}")
    m = re.fullmatch(r"(\d{1,5})x(\d{1,5})", a.size)
    if not m or min(int(m.group(1)), int(m.group(2))) < 1:
        raise BenchError(f"--size: expected WIDTHxHEIGHT of positive integers, got {a.size!r}")
    a.isowall = a.isowall_given = os.path.join(a.build, "bin", "isowall")
    if not os.path.exists(a.isowall):
        raise BenchError(f"--build: {a.isowall} not found; build first (bash scripts/setup.sh)")
    a.data_given = a.data is not None
    a.data = a.data if a.data_given else DEFAULT_DATA
    a.volumes = [v for v in a.volumes.split(",") if v]
    return a


def suggested_isovalues(readme):
    """{volume: [iso, ...]} in the README's order, from its "Suggested isovalues" table."""
    isos = {}
    with open(readme, encoding="utf-8") as f:
        lines = f.read().splitlines()
    try:
        start = next(i for i, line in enumerate(lines) if re.match(r"^#+\s*Suggested isovalues", line))
    except StopIteration:
        return isos
    in_table = False
    for line in lines[start + 1:]:
        if line.startswith("|"):
            in_table = True
            m = re.match(r"^\|\s*`([^`]+)`\s*\|\s*(-?[\d.]+)\s*\|", line)
            if m:
                isos.setdefault(m.group(1), []).append(float(m.group(2)))
        elif in_table:
            break  # the end of the first table
    return isos


def cases(a):
    """[(volume name, .nhdr path, iso)], or None (after saying why) when there is no data."""
    if not os.path.isdir(a.data):
        if a.data_given:
            raise BenchError(f"--data: {a.data} not found")
        print(f"bench_defaults: skipped: {a.data} not found (../shared/data or $ISOWALL_SHARED_DATA)")
        return None
    found = {os.path.basename(p)[:-5]: p for p in sorted(glob.glob(os.path.join(a.data, "*.nhdr")))}
    if not found:
        print(f"bench_defaults: skipped: no *.nhdr in {a.data}")
        return None
    unknown = [v for v in a.volumes if v not in found]
    if unknown:
        raise BenchError(f"--volumes: {', '.join(unknown)} not in {a.data} (there: {', '.join(found)})")
    readme = os.path.join(a.data, "README.md")
    if not os.path.exists(readme):
        raise BenchError(f"--data: {readme} not found (it gives the suggested isovalues)")
    isos = suggested_isovalues(readme)
    names = [v for v in isos if v in found] + [v for v in found if v not in isos]
    out = []
    for name in names:
        if a.volumes and name not in a.volumes:
            continue
        if name not in isos:
            print(f"{name}: skipped: no suggested isovalues in {readme}")
            continue
        out += [(name, found[name], iso) for iso in isos[name]]
    if not out:
        raise BenchError(f"--data: no volume in {a.data} has suggested isovalues in its README.md")
    return out


def run(cmd, what):
    """stdout of `cmd`; a failure is one BenchError line naming `what` and the last stderr line."""
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    except subprocess.TimeoutExpired:
        raise BenchError(f"{what}: no answer within an hour: {' '.join(cmd)}")
    except OSError as e:
        raise BenchError(f"{what}: {e.strerror}: {cmd[0]}")
    if proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["(no message)"])[-1]
        status = f"signal {-proc.returncode}" if proc.returncode < 0 else f"exit {proc.returncode}"
        raise BenchError(f"{what}: {status}: {last}")
    return proc.stdout


def snapshot(a, tmp):
    """Runs every frame from a private copy of isowall, so that a rebuild of --build during the
    sweep (a peer at work on the same tree) neither stops it nor mixes two builds' timings."""
    copy = os.path.join(tmp, "isowall")
    shutil.copy2(a.isowall, copy)
    run([copy, "render", "--help"], "--build: the copy of isowall")
    with open(copy, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()[:16]
    built = time.strftime("%Y-%m-%d %H:%M", time.localtime(os.path.getmtime(a.isowall)))
    a.isowall = copy
    return {"path": a.isowall_given, "built": built, "sha256_16": digest}


def render(a, path, iso, value, tmp):
    """One timed frame: time to C = 99% (share of final pixels) and of every ray, from the timeline."""
    csv_path = os.path.join(tmp, "timeline.csv")
    run([a.isowall, "render", "-v", path, "--iso", f"{iso:g}", "--size", a.size, "--warm-up", "-q",
         "--timeline", csv_path, "--out", os.path.join(tmp, "frame.png"), f"--{a.option}", str(value)],
        f"isowall render --{a.option} {value} ({os.path.basename(path)}, iso {iso:g})")
    with open(csv_path) as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    hit = next((r for r in rows if r["final_pixels"] >= 0.99), None)
    return {"c99_s": hit["time_s"] if hit else None, "triangles_c99": int(hit["triangles"]) if hit else None,
            "rays_c99": int(hit["rays"]) if hit else None, "every_ray_s": rows[-1]["time_s"],
            "triangles": int(rows[-1]["triangles"]), "rays": int(rows[-1]["rays"])}


def measure_case(a, k, name, path, iso, tmp):
    """Every run of one case: --runs rounds of every value, the order rotated round by round."""
    runs = []
    n = len(a.values)
    for r in range(a.runs):
        shift = (r + k) % n  # rotated from round to round, and from case to case
        for pos, value in enumerate(a.values[shift:] + a.values[:shift]):
            res = render(a, path, iso, value, tmp)
            res.update({"round": r, "position": pos, "value": value, "load_1min": round(os.getloadavg()[0], 2)})
            runs.append(res)
    median = {}
    for v in a.values:
        mine = [x for x in runs if x["value"] == v]
        c99 = [x["c99_s"] for x in mine if x["c99_s"] is not None]
        median[v] = {"c99_s": statistics.median(c99) if len(c99) == len(mine) else None,
                     "every_ray_s": statistics.median(x["every_ray_s"] for x in mine)}
    return {"volume": name, "path": path, "iso": iso, "runs": runs, "median": median}


def choose(a, results):
    """Ratios per case, worst ratio and geometric mean per value, and the value the rule picks."""
    for res in results:
        meds = [res["median"][v]["c99_s"] for v in a.values]
        if any(m is None for m in meds):
            raise BenchError(f"--values: a run of {res['volume']} iso {res['iso']:g} never reached C = 99%")
        best = min(meds)
        res["ratio"] = {v: res["median"][v]["c99_s"] / best for v in a.values}
        res["best"] = min(a.values, key=lambda v: (res["ratio"][v], v))
    worst = {v: max(res["ratio"][v] for res in results) for v in a.values}
    geo = {v: math.exp(statistics.fmean(math.log(res["ratio"][v]) for res in results)) for v in a.values}
    chosen = min(a.values, key=lambda v: (round(worst[v], 9), round(geo[v], 9), v))
    return worst, geo, chosen


def report(a, meta, results, worst, geo, chosen):
    head = "| volume, iso | " + " | ".join(f"{a.option} {v}" for v in a.values) + " |"
    rule = "|---" * (len(a.values) + 1) + "|"
    lines = [f"# Default of --{a.option}: a sweep over every shared volume", "",
             f"{meta['date']}, {meta['cores']} cores, load average (1/5/15 min) {meta['load_start']} at "
             f"the start and {meta['load_end']} at the end; {a.size}, `isowall render --warm-up` (built "
             f"{meta['isowall']['built']}) with every other option at its default; each cell is the median "
             f"of {a.runs} run(s) (a round of every value per run, in a rotated order). Time to C = 99% "
             f"(share of final pixels), seconds, and (its ratio to the case's best):", "", head, rule]
    for res in results:
        cells = [f"{res['median'][v]['c99_s']:.3f} ({res['ratio'][v]:.2f})" for v in a.values]
        lines.append(f"| {res['volume']} {res['iso']:g} | " + " | ".join(cells) + " |")
    lines.append("| worst ratio | " + " | ".join(f"{worst[v]:.2f}" for v in a.values) + " |")
    lines.append("| geometric mean | " + " | ".join(f"{geo[v]:.2f}" for v in a.values) + " |")
    lines += ["", f"{RULE}.", "", f"chosen: --{a.option} {chosen} (worst ratio {worst[chosen]:.2f}, "
              f"geometric mean {geo[chosen]:.2f})", "",
              "Best value per case: " + "; ".join(f"{r['volume']} {r['iso']:g}: {r['best']}" for r in results)
              + ".", "", "Every ray (median s, for reference; not part of the rule):", "", head, rule]
    for res in results:
        lines.append(f"| {res['volume']} {res['iso']:g} | "
                     + " | ".join(f"{res['median'][v]['every_ray_s']:.3f}" for v in a.values) + " |")
    lines += ["", f"{meta['frames']} timed frames in {meta['total_s']:.0f} s."]
    return "\n".join(lines) + "\n"


def main(argv):
    a = parse_args(argv)
    todo = cases(a)
    if todo is None:
        return 0
    os.makedirs(a.out, exist_ok=True)
    print(f"{len(todo)} cases x {len(a.values)} values x {a.runs} runs: --{a.option} "
          f"{','.join(map(str, a.values))}, {a.size}", flush=True)
    print(RULE, flush=True)
    load_start = "/".join(f"{x:.2f}" for x in os.getloadavg())
    t0 = time.monotonic()
    tmp = tempfile.mkdtemp(prefix="isowall-defaults-")
    results = []
    try:
        binary = snapshot(a, tmp)
        done = set()
        for k, (name, path, iso) in enumerate(todo):
            if name not in done:  # builds the octree cache once, outside the timings
                run([a.isowall, "info", "-v", path], f"isowall info ({name})")
                done.add(name)
            t1 = time.monotonic()
            res = measure_case(a, k, name, path, iso, tmp)
            results.append(res)
            print(f"{name} {iso:g}: C99 median s " + ", ".join(
                f"{v}: {res['median'][v]['c99_s']:.3f}" for v in a.values)
                + f" ({time.monotonic() - t1:.0f} s)", flush=True)
            with open(os.path.join(a.out, "defaults.partial.json"), "w") as f:
                json.dump({"binary": binary, "cases": results}, f, indent=1)  # so far
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    worst, geo, chosen = choose(a, results)
    meta = {"option": a.option, "values": a.values, "runs": a.runs, "size": a.size, "rule": RULE,
            "statistic": "median of runs", "date": time.strftime("%Y-%m-%d %H:%M"), "cores": os.cpu_count(),
            "load_start": load_start, "load_end": "/".join(f"{x:.2f}" for x in os.getloadavg()),
            "total_s": round(time.monotonic() - t0, 1), "frames": sum(len(r["runs"]) for r in results),
            "isowall": binary, "data": a.data}
    text = report(a, meta, results, worst, geo, chosen)
    print(text)
    with open(os.path.join(a.out, "defaults.md"), "w") as f:
        f.write(text)
    with open(os.path.join(a.out, "defaults.json"), "w") as f:
        json.dump({"meta": meta, "cases": results, "worst_ratio": worst, "geometric_mean": geo,
                   "chosen": chosen}, f, indent=1)
    os.remove(os.path.join(a.out, "defaults.partial.json"))
    print(f"wrote {a.out}/defaults.md, defaults.json")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except BenchError as e:
        print(f"bench_defaults: error: {e}", file=sys.stderr)
        sys.exit(1)
