#!/usr/bin/python3
"""Progressive LOD chosen by the server against always and never: seconds to C = 90% and 99% for
a new isovalue with `isowall view` (front view, 800x600, no cache, --encoding auto) with
`--no-lod`, `--lod` and the default (the server sends the coarse passes where it forecasts that
their picture reaches C = 0.88 or more, remote/lod_choice.h), on every shared volume at its README
isovalues, at each --rates link (serve --rate-mbps).

Usage: scripts/bench_lod_choice.py [--isowall build/bin/isowall] [--data ../shared/data]
                                   [--rates 1,100] [--only NAME] [--volume NAME=PATH:ISO ...]
                                   [--runs N]

Each row also prints the server's forecast of the coarse picture's C (its log line per request)
and the C the client measured when the coarse passes had drawn (`--lod`'s run). The verdict says
whether the default came within 10% of the sooner of the other two to C = 90%. With --runs N the
three modes run in turn N times and each figure is the median (one run of a frame that takes
tens of milliseconds moves by 20-40% here; in turn, the same frame's median moves by a few %). The server runs on CPU 0 and the client on CPU 1. Errors are
one line on stderr and exit status 1; the server is always stopped.
"""
import argparse
import os
import re
import subprocess
import sys
import time

from bench_remote_bytes import CASES, ROOT, stop_server

PROG = "bench_lod_choice.py"
PORT = 7983
MODES = [("no LOD", ["--no-lod"]), ("LOD", ["--lod"]), ("chosen", [])]


def fail(msg):
    print(f"{PROG}: error: {msg}", file=sys.stderr)
    sys.exit(1)


def start_server(isowall, datasets, rate, log_path):
    # Line-buffered: each request's log line is in the file when its view ends.
    args = ["stdbuf", "-oL", "taskset", "-c", "0", isowall, "serve", "--listen",
            f"127.0.0.1:{PORT}"]
    for name, path in datasets.items():
        args += ["--dataset", f"{name}={path}"]
    args += ["--rate-mbps", str(rate)]
    log = open(log_path, "w")
    proc = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, text=True)
    deadline = time.time() + 300
    while time.time() < deadline:
        with open(log_path) as f:
            if "listening on" in f.read():
                return proc
        if proc.poll() is not None:
            break
        time.sleep(0.2)
    proc.kill()
    fail(f"isowall serve did not start listening (see {log_path})")


def last_forecast(log_path):
    with open(log_path) as f:
        found = re.findall(r"coarse picture forecast C = ([\d.]+) \((\d+) rays, ([\d.]+) ms\): "
                           r"(\d) coarse levels", f.read())
    return (float(found[-1][0]), int(found[-1][3]), float(found[-1][2])) if found else \
        (None, None, None)


def view(isowall, name, iso, extra):
    out = subprocess.run(
        ["taskset", "-c", "1", isowall, "view", "--connect", f"127.0.0.1:{PORT}", "--dataset",
         name, "--iso", str(iso), "--out", f"/tmp/{PROG}-{name}-{iso}.png"] + extra,
        capture_output=True, text=True, timeout=900)
    if out.returncode != 0:
        fail(f"isowall view {name} {iso} {' '.join(extra)}: {out.stderr.strip()[-300:]}")
    found = {float(m.group(1)): float(m.group(2))
             for m in re.finditer(r"C >=\s+([\d.]+)%:\s+([\d.]+) s", out.stdout)}
    if 90.0 not in found or 99.0 not in found:
        fail(f"isowall view {name} {iso}: no C figures in: {out.stdout[-300:]}")
    coarse = re.search(r"coarse passes: C = ([\d.]+)", out.stdout)
    return found[90.0], found[99.0], float(coarse.group(1)) if coarse else None


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--isowall", default=os.path.join(ROOT, "build", "bin", "isowall"))
    p.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data"))
    p.add_argument("--rates", default="1,100", help="link rates in Mbit/s, comma-separated")
    p.add_argument("--only", help="one shared volume's name")
    p.add_argument("--volume", action="append", default=[],
                   help="another volume as NAME=PATH:ISO (repeatable)")
    p.add_argument("--runs", type=int, default=1, help="runs of each mode, the median kept (1)")
    a = p.parse_args()
    if a.runs < 1:
        fail(f"--runs: expected at least 1, got {a.runs}")
    try:
        rates = [float(r) for r in a.rates.split(",")]
    except ValueError:
        fail(f"--rates: expected numbers separated by commas, got {a.rates!r}")
    if not rates or min(rates) <= 0:
        fail(f"--rates: expected rates above 0, got {a.rates!r}")
    cases = [c for c in CASES if not a.only or c[0] == a.only]
    datasets = {n: os.path.join(a.data, n + ".nhdr") for n, _ in cases}
    for v in a.volume:
        m = re.fullmatch(r"([\w-]+)=(.+):([-\d.eE+]+)", v)
        if not m:
            fail(f"--volume: expected NAME=PATH:ISO, got {v!r}")
        datasets[m.group(1)] = m.group(2)
        cases.append((m.group(1), float(m.group(3))))
    if not cases:
        fail(f"--only: no volume named {a.only!r}")
    for n, path in datasets.items():
        if not os.path.exists(path):
            fail(f"--data or --volume: {path} does not exist")
    log_path = f"/tmp/{PROG}-serve.log"
    runs = f", the median of {a.runs} runs in turn" if a.runs > 1 else ", one run"
    print("`isowall view` (front view, 800x600, new isovalue, --encoding auto), server on CPU 0 "
          "and client on CPU 1: seconds to C = 90 / 99% with --no-lod, --lod and the default "
          f"(chosen by the server){runs}\n")
    print("| Mbit/s | volume | iso | no LOD | LOD | chosen | forecast C (its time) | drawn coarse C "
          "| chose | verdict |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---|---|")
    held = total = 0
    for rate in rates:
        server = start_server(a.isowall, datasets, rate, log_path)
        try:
            for name, iso in cases:
                runs = {mode: [] for mode, _ in MODES}
                for _ in range(a.runs):
                    for mode, extra in MODES:
                        runs[mode].append(view(a.isowall, name, iso, extra))
                # Each mode's run of median time to C = 90%.
                got = {m: sorted(r, key=lambda x: x[0])[len(r) // 2] for m, r in runs.items()}
                forecast, levels, forecast_ms = last_forecast(log_path)
                best = min(got["no LOD"][0], got["LOD"][0])
                ok = got["chosen"][0] <= 1.1 * best
                held += ok
                total += 1
                cols = " | ".join(f"{got[m][0]:.3f} / {got[m][1]:.3f}" for m, _ in MODES)
                drawn = got["LOD"][2]
                print(f"| {rate:g} | {name} | {iso:g} | {cols} | "
                      f"{f'{forecast} ({forecast_ms:g} ms)' if forecast is not None else '-'} | "
                      f"{f'{drawn:.3f}' if drawn is not None else '-'} | "
                      f"{'LOD' if levels else 'no LOD'} | "
                      f"{'holds' if ok else 'LATER'} ({got['chosen'][0] / best:.2f}) |",
                      flush=True)
        finally:
            stop_server(server)
    print(f"\nthe default reached C = 90% within 10% of the sooner of --no-lod and --lod on "
          f"{held} of {total} rows")


if __name__ == "__main__":
    main()
