#!/usr/bin/python3
"""The remote-viewing study of the dissertation's section 4.2: bytes and time to C = 90, 99, 99.9
and 100% for each test case, over links paced to 100, 10 and 1 Mbit/s.

Usage: scripts/remote_study.py [--isowall build/bin/isowall] [--volume PATH|phantom]
                               [--iso 40] [--size 800x600] [--turn 30] [--rates 100,10,1]
                               [--cases 1,2,3,4,5,6,7] [--out out/remote-study]

The volume defaults to the shared CT head resampled to 256 voxels a side (256x256x117, made once
by scripts/resample_volume.py into build/data), the nearest to the text's 256x256x209 Visible
Woman head. For each rate one `isowall serve --rate-mbps R` runs on loopback, and each case is
one `isowall view --case K` against it:
  1 base (separate vertices), 2 indexed face sets, 3 + progressive LOD: a new isovalue, the
  front view; 4 + cached groups: the front view, then the view turned by --turn degrees, which
  is measured; 5 ours (quantised, index-coded, zstd + LOD + cache), measured as 4 (its first
  frame is also reported, as "5 new"); 6 as 5 in the cells encoding, and 7 as 5 with
  the server choosing cells or compact+zstd per group (view --encoding auto), both measured as 5.
Times are the client's wall clock from sending the request (server and client share this
machine's two cores). Each case runs once at each rate: every figure is from 1 run, no median.
Writes study.json, study.md (the tables, beside the text's, with the targets below),
correctness-vs-time plots like Figures 4.4-4.6 (c_vs_time.png, one panel per rate) and C against
bytes (c_vs_bytes.png), each run's timeline CSV and final image.

The targets, one verdict line (holds / MISSED) for every case in the tables:
  bytes to each C at most half the text's Table 4.1, scaled for the size of the volume;
  time to C = 90% at 1 Mbit/s at most 1/5 of the text's Table 4.4, not scaled.
Case 5 with cache is judged against the text's case 4 (the same turned view), "5 ours, new iso"
against the text's best new-isovalue case at each C (the smallest of cases 1-3).
The size rule: an isosurface's bytes grow with the number of cells its surface crosses. The
text's head is 256x256x209 voxels; the default head here has the same 256x256 slices but 117 of
them, and a head's surface (mostly its sides) crosses cells in proportion to the slices, so the
text's bytes are multiplied by our voxels over its voxels (117/209 = 0.560 for the default head).
For volumes of other widths this is cruder: scaled alike on every axis, a surface's cells grow as
the voxels to the power 2/3. The volume's size comes from `isowall info`; the report prints the
factor.
Errors are one line on stderr and exit status 1; every server started is stopped.
"""
import argparse
import csv
import json
import os
import re
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROG = "remote_study.py"
THRESHOLDS = [0.90, 0.99, 0.999, 1.0]
CASE_NAMES = {"1": "1 base", "2": "2 indexed", "3": "3 + LOD", "4": "4 + cache",
              "5new": "5 ours, new iso", "5": "5 ours + cache",
              "6new": "6 cells, new iso", "6": "6 cells + cache",
              "7new": "7 auto, new iso", "7": "7 auto + cache"}
# The cases measured twice: the front view at a new isovalue, then the turned view from the cache.
CACHED = ("4", "5", "6", "7")

# The dissertation's Tables 4.1-4.4 (rows C = 90, 99, 99.9, 100%; columns cases 1-4).
TEXT_BYTES = {"1": [16.7e6, 24.2e6, 24.3e6, 24.3e6], "2": [4.0e6, 6.4e6, 6.4e6, 6.4e6],
              "3": [1.0e6, 9.7e6, 10.9e6, 10.9e6], "4": [73, 0.3e6, 1.2e6, 1.2e6]}
TEXT_TIMES = {
    100: {"1": [4.09, 5.9, 7.41, 7.46], "2": [1.3, 2.26, 3.71, 3.98],
          "3": [0.54, 2.61, 4.78, 4.85], "4": [0.08, 0.47, 1.54, 2.64]},
    10: {"1": [16.89, 24.56, 26.11, 26.38], "2": [4.35, 7.11, 8.62, 8.68],
         "3": [1.39, 11.05, 14.32, 14.6], "4": [0.23, 0.93, 2.89, 3.98]},
    1: {"1": [153.87, 224.63, 226.7, 226.98], "2": [37.38, 60.22, 61.89, 61.95],
        "3": [9.13, 90.4, 103.51, 103.79], "4": [0.23, 3.31, 12.41, 13.49]},
}
TEXT_DIMS = (256, 256, 209)  # the text's Visible Woman head
# The text's cases each of ours is judged against, the smallest of them at each C: case 5 with
# cache shows the turned view of case 4; a new isovalue in our encoding against the text's best
# for a new isovalue.
AGAINST = {"1": ["1"], "2": ["2"], "3": ["3"], "4": ["4"], "5": ["4"], "5new": ["1", "2", "3"],
           "6": ["4"], "6new": ["1", "2", "3"], "7": ["4"], "7new": ["1", "2", "3"]}


class StudyError(Exception):
    pass


def default_volume():
    src = os.path.join(ROOT, "..", "shared", "data", "vhp_ct_head.nhdr")
    if not os.path.exists(src):
        raise StudyError(f"--volume: the default needs {os.path.normpath(src)}, which is absent; "
                         "give --volume PATH or --volume phantom")
    out_dir = os.path.join(ROOT, "build", "data")
    run([sys.executable, os.path.join(ROOT, "scripts", "resample_volume.py"), src,
         "--scale", "0.5", "--out-dir", out_dir], "resample_volume.py")
    return os.path.join(out_dir, "vhp_ct_head_256x256x117.nhdr")


def volume_dims(isowall, volume):
    """The volume's voxels a side, from `isowall info` (the phantom is built into isowall)."""
    out = run([isowall, "info"] + ([] if volume == "phantom" else ["-v", volume]), "isowall info")
    m = re.search(r"^volume: .*\s(\d+)x(\d+)x(\d+)\s+\S+\s+spacing", out, re.M)
    if not m:
        raise StudyError("isowall info: no 'volume: NAME WxHxD TYPE spacing' line")
    return [int(g) for g in m.groups()]


def size_scale(dims):
    """The factor for the text's bytes: our voxels over the text's (see the docstring).

    Not the ratio of triangles sent: those are what each case's view-dependent selection makes,
    so dividing by them would judge bytes a triangle only, and the text gives no triangle count
    of its own (about 337,000 is its case 1 bytes over 72 bytes a triangle).
    """
    return (dims[0] * dims[1] * dims[2]) / (TEXT_DIMS[0] * TEXT_DIMS[1] * TEXT_DIMS[2])


def run(cmd, what, timeout=1800):
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if p.returncode != 0:
        last = (p.stderr.strip() or p.stdout.strip()).splitlines()
        raise StudyError(f"{what}: exit {p.returncode}: {last[-1] if last else 'no output'}")
    return p.stdout


class Server:
    """`isowall serve` on a free loopback port, stopped on exit."""

    def __init__(self, isowall, volume, rate):
        cmd = [isowall, "serve", "--port", "0", "--quiet"]
        if volume != "phantom":
            cmd += ["--dataset", f"study={volume}"]
        if rate > 0:
            cmd += ["--rate-mbps", str(rate)]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
        self.port = None
        deadline = time.monotonic() + 120
        lines = []
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            lines.append(line.strip())
            m = re.search(r"listening on 127\.0\.0\.1:(\d+)", line)
            if m:
                self.port = int(m.group(1))
                return
        self.stop()
        raise StudyError("isowall serve: no 'listening on' line: " + " | ".join(lines[-3:]))

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def read_frames(path):
    """Timeline CSV of isowall view -> {frame: [rows]} (time_s, bytes, ... as numbers)."""
    frames = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            r = {k: float(v) for k, v in row.items()}
            frames.setdefault(int(r["frame"]), []).append(r)
    return frames


def first_reaching(rows, th):
    for r in rows:
        if r["c"] >= th - 1e-12:
            return r
    return None


def summarise(rows):
    out = {"points": [], "total_bytes": rows[-1]["bytes"], "total_s": rows[-1]["time_s"],
           "curve": [(r["time_s"], r["bytes"], r["c"]) for r in rows]}
    for th in THRESHOLDS:
        r = first_reaching(rows, th)
        out["points"].append(None if r is None else {"time_s": r["time_s"], "bytes": r["bytes"]})
    return out


def run_case(a, port, rate, case, out_dir):
    tag = f"{rate}mbps_case{case}"
    csv_path = os.path.join(out_dir, tag + ".csv")
    png = os.path.join(out_dir, tag + ".png")
    cmd = [a.isowall, "view", "--connect", f"127.0.0.1:{port}", "--case", case,
           "--size", a.size, "-o", png, "--timeline", csv_path, "--timeout", "600"]
    cmd += ["--dataset", "phantom"] if a.volume == "phantom" else ["--dataset", "study"]
    cmd += ["--iso", str(a.iso)]
    if case in CACHED:
        script = os.path.join(out_dir, "turn.txt")
        with open(script, "w") as f:
            f.write(f"wait done\norbit {a.turn} 0\nwait done\n")
        cmd += ["--script", script]
    run(cmd, f"isowall view --case {case} at {rate} Mbit/s")
    frames = read_frames(csv_path)
    results = {}
    if case in CACHED:
        results[case] = summarise(frames[max(frames)])
        if case != "4":
            results[case + "new"] = summarise(frames[min(frames)])
    else:
        results[case] = summarise(frames[min(frames)])
    return results


def fmt_bytes(b):
    if b is None:
        return "-"
    if b >= 1e6:
        return f"{b / 1e6:.2f}M"
    if b >= 1e3:
        return f"{b / 1e3:.1f}K"
    return f"{int(b)}"


def fmt_s(s):
    return "-" if s is None else (f"{s:.3f}" if s < 10 else f"{s:.1f}")


def table(title, cols, cell, text=None):
    lines = [f"**{title}**", "", "| C | " + " | ".join(CASE_NAMES[c] for c in cols) + " |",
             "|---|" + "---|" * len(cols)]
    for i, th in enumerate(THRESHOLDS):
        cells = []
        for c in cols:
            s = cell(c, i)
            if text and c in text:
                s += f" ({text[c][i]})"
            cells.append(s)
        lines.append(f"| {100 * th:g}% | " + " | ".join(cells) + " |")
    return lines


def point(res, rate, case, i, key):
    p = res.get(str(rate), {}).get(case, {}).get("points", [None] * 4)[i]
    return None if p is None else p[key]


def report(res, rates, cols, dims):
    """The tables (ours, with the text's in brackets) and the targets."""
    base = str(max(rates))
    lines = table(f"Bytes to reach C (at {base} Mbit/s; the text's Table 4.1 in brackets)", cols,
                  lambda c, i: fmt_bytes(point(res, base, c, i, "bytes")),
                  {c: [fmt_bytes(v) for v in TEXT_BYTES[c]] for c in TEXT_BYTES})
    for rate in rates:
        text = TEXT_TIMES.get(rate, {})
        n = {100: "4.2", 10: "4.3", 1: "4.4"}.get(rate)
        title = f"Seconds to reach C at {rate} Mbit/s" + (f" (Table {n} in brackets)" if n else "")
        lines += [""] + table(title, cols, lambda c, i, r=rate: fmt_s(point(res, r, c, i, "time_s")),
                              {c: [f"{v:g}" for v in text[c]] for c in text})
    return lines + ["", "**Targets**", ""] + target_rules(dims) + \
        byte_targets(res, base, cols, size_scale(dims)) + time_targets(res, rates, cols)


def target_rules(dims):
    ours, text = (f"{d[0]}x{d[1]}x{d[2]}" for d in (dims, TEXT_DIMS))
    return ["Every figure is from 1 run each (one `isowall view` per case and rate; no median).",
            f"- scale factor for the volume's size: {size_scale(dims):.3f} = {ours} / {text} "
            "voxels. The byte limits are half the text's Table 4.1 times this factor: an "
            "isosurface's bytes grow with the cells its surface crosses, and on the text's "
            "256x256 slices (the default head's) a head's surface crosses cells in proportion "
            "to the number of slices. Time limits are 1/5 of Table 4.4, not scaled.",
            "- case 5 (with cache) is judged against the text's case 4, \"5 ours, new iso\" "
            "against the text's best new-isovalue case (1-3) at each C."]


def text_best(table, case, i):
    """The text's smallest figure in row i among the cases ours is judged against, and its case."""
    return min((table[c][i], c) for c in AGAINST[case] if c in table)


def verdict(got, limit):
    return "holds" if got is not None and got <= limit else "MISSED"


def byte_targets(res, base, cols, scale):
    lines = []
    for c in cols:
        for i, th in enumerate(THRESHOLDS):
            got = point(res, base, c, i, "bytes")
            text, tc = text_best(TEXT_BYTES, c, i)
            limit = text / 2 * scale
            lines.append(f"- bytes, case {c}, C = {100 * th:g}%: {fmt_bytes(got)} against "
                         f"<= {fmt_bytes(limit)} (half the text's case {tc}, {fmt_bytes(text)}, "
                         f"x {scale:.3f}): {verdict(got, limit)}")
    return lines


def time_targets(res, rates, cols):
    if 1 not in rates:
        return ["- time to C = 90% at 1 Mbit/s: not judged (1 Mbit/s is not among --rates)"]
    lines = []
    for c in cols:
        got = point(res, "1", c, 0, "time_s")
        text, tc = text_best(TEXT_TIMES[1], c, 0)
        lines.append(f"- time to C = 90% at 1 Mbit/s, case {c}: {fmt_s(got)} s against "
                     f"<= {text / 5:.3f} s (1/5 of the text's case {tc}, {text:g} s): "
                     f"{verdict(got, text / 5)}")
    return lines


def plot(res, rates, cols, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(rates), figsize=(5.2 * len(rates), 4.2), squeeze=False)
    for ax, rate in zip(axes[0], rates):
        for c in cols:
            r = res.get(str(rate), {}).get(c)
            if not r:
                continue
            t = [max(p[0], 1e-3) for p in r["curve"]]
            ax.step(t, [100 * p[2] for p in r["curve"]], where="post", label=CASE_NAMES[c])
        ax.set_xscale("log")
        ax.set_ylim(0, 101)
        ax.axhline(90, color="grey", lw=0.5, ls=":")
        ax.set_xlabel("time since the request (s, log)")
        ax.set_ylabel("correctness C (%)")
        ax.set_title(f"{rate} Mbit/s")
        ax.grid(alpha=0.3)
    axes[0][0].legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "c_vs_time.png"), dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    base = str(max(rates))
    for c in cols:
        r = res.get(base, {}).get(c)
        if r:
            ax.step([max(p[1], 1) for p in r["curve"]], [100 * p[2] for p in r["curve"]],
                    where="post", label=CASE_NAMES[c])
    ax.set_xscale("log")
    ax.set_ylim(0, 101)
    ax.set_xlabel("bytes received (log)")
    ax.set_ylabel("correctness C (%)")
    ax.set_title("C against bytes (Table 4.1 as curves)")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "c_vs_bytes.png"), dpi=110)
    plt.close(fig)


def parse_args(argv):
    p = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n")[0])
    p.add_argument("--isowall", default=os.path.join(ROOT, "build", "bin", "isowall"))
    p.add_argument("--volume", help="NRRD volume, or 'phantom' (default: the 256-wide head)")
    p.add_argument("--iso", type=float, default=None, help="isovalue (head: 40, phantom: 50)")
    p.add_argument("--size", default="800x600")
    p.add_argument("--turn", type=float, default=30.0, help="the rotation of cases 4 and 5")
    p.add_argument("--rates", default="100,10,1", help="Mbit/s, comma-separated")
    p.add_argument("--cases", default="1,2,3,4,5,6,7")
    p.add_argument("--out", default=os.path.join(ROOT, "out", "remote-study"))
    a = p.parse_args(argv)
    try:
        a.rates = [int(r) if float(r).is_integer() else float(r) for r in a.rates.split(",")]
    except ValueError:
        raise StudyError(f"--rates: expected numbers separated by commas, got {a.rates!r}")
    if not a.rates or min(a.rates) <= 0:
        raise StudyError(f"--rates: each rate must be above 0 Mbit/s, got {a.rates}")
    a.cases = a.cases.split(",")
    bad = [c for c in a.cases if c not in ("1", "2", "3", "4", "5", "6", "7")]
    if bad:
        raise StudyError(f"--cases: expected cases among 1..7, got {','.join(bad)}")
    if not os.access(a.isowall, os.X_OK):
        raise StudyError(f"--isowall: {a.isowall} is not an executable (build first)")
    if a.volume is None:
        a.volume = default_volume()
    elif a.volume != "phantom" and not os.path.exists(a.volume):
        raise StudyError(f"--volume: {a.volume} does not exist")
    if a.iso is None:
        a.iso = 50.0 if a.volume == "phantom" else 40.0
    return a


def main(argv):
    a = parse_args(argv)
    dims = volume_dims(a.isowall, a.volume)
    os.makedirs(a.out, exist_ok=True)
    res = {}
    for rate in a.rates:
        server = Server(a.isowall, a.volume, rate)
        try:
            for case in a.cases:
                t0 = time.monotonic()
                got = run_case(a, server.port, rate, case, a.out)
                res.setdefault(str(rate), {}).update(got)
                r = got[case]
                print(f"study: {rate} Mbit/s, case {case}: {fmt_bytes(r['total_bytes'])}B in "
                      f"{r['total_s']:.2f} s, C = 90% at {fmt_s((r['points'][0] or {}).get('time_s'))} s "
                      f"({time.monotonic() - t0:.0f} s run)", flush=True)
        finally:
            server.stop()
    cols = [c for c in ["1", "2", "3", "4", "5new", "5", "6new", "6", "7new", "7"]
            if any(c in res[str(r)] for r in a.rates)]
    lines = [f"Volume {a.volume}, iso {a.iso:g}, {a.size}, turn {a.turn:g} degrees for 4 and 5.",
             ""] + report(res, a.rates, cols, dims)
    with open(os.path.join(a.out, "study.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(a.out, "study.json"), "w") as f:
        json.dump({"volume": a.volume, "dims": dims, "scale": size_scale(dims), "iso": a.iso,
                   "size": a.size, "turn": a.turn, "runs_each": 1, "results": res}, f, indent=1)
    plot(res, a.rates, cols, a.out)
    print("\n".join(lines))
    print(f"study: wrote {a.out}/study.md, study.json, c_vs_time.png, c_vs_bytes.png")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except StudyError as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        sys.exit(1)
    except subprocess.TimeoutExpired as e:
        print(f"{PROG}: {e.cmd[0]} {e.cmd[1]}: no result after {e.timeout} s", file=sys.stderr)
        sys.exit(1)
