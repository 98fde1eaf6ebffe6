#!/usr/bin/python3
"""Resolution insensitivity on every shared volume: for each volume in the data folder
at each isovalue its README suggests, at 1x, 2x and 4x a side where that fits in memory, the
default `isowall render` (no engine option, warm, 1600x1200, front view) timed to C = 90/99/99.9%
against the full surface at full resolution (`--against-full`: the truth, not the engine's own
final image) and against its own final image, the final image against the truth (C, coverage
IoU), the triangles drawn by C = 99%, the FE + Embree peer at the same size (VTK flying edges
on 2 threads, an Embree BVH and primary rays; scripts/fe_mesh.py and bench/peer), and the peak
memory (RSS) of `isowall render` as a user runs it: once with no option but the volume, the
isovalue and the size, and once with --warm-up (a second frame, as a wall's frames find the
process; a volume of 256 MiB or more is then copied into huge pages). The timed runs compare with
the full surface and the truth, whose renders would set their peak, so they are not used for it.

Usage: /usr/bin/python3 scripts/bench_volumes.py [--scales 1,2,4] [--volumes engine,tooth]
           [--isos first|all] [--runs 3] [--size 1600x1200] [--build build]
           [--data ../shared/data] [--out out/bench-volumes] [--no-peer] [--memory-share 0.6]

Copies at 2x and 4x are made once by scripts/resample_volume.py into BUILD/data (as
bench_scaling.py makes them). A scale is skipped, and says so, when the volume twice (the copy in
huge pages beside the map) and the full surface (the README's marching-cubes triangles times the
scale squared, at 48 bytes a triangle) would pass --memory-share of the memory available now.
Writes OUT/volumes.md (a table per volume, the targets, the worst case), OUT/volumes.json and
OUT/volumes-NAME.png (time to C = 99% against voxels, log-log, per isovalue, with the peer).
Errors: one line naming the option or the program, exit 1.
"""
import argparse
import json
import math
import os
import re
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import bench_scaling as bs  # noqa: E402
from bench_volumes_report import plot_volume, report  # noqa: E402
from resample_volume import InputError, read_header  # noqa: E402

BYTES_PER_TRIANGLE = 48  # the full surface's mesh and its draw buffers


def parse_args(argv):
    ap = bs.Parser(description=__doc__.split("\n\n")[0], epilog=__doc__.split("\n\n", 1)[1],
                   formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scales", default="1,2,4")
    ap.add_argument("--volumes", default="", help="comma-separated names (default: every .nhdr in --data)")
    ap.add_argument("--isos", choices=("first", "all"), default="all",
                    help="the README's isovalues of each volume: all, or the first only")
    ap.add_argument("--runs", type=int, default=3, help="runs of each case, the median kept")
    ap.add_argument("--size", default="1600x1200")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench-volumes"))
    ap.add_argument("--no-peer", action="store_true", help="leave FE + Embree out")
    ap.add_argument("--memory-share", type=float, default=0.6,
                    help="share of the available memory a case may plan to use (default %(default)s)")
    a = ap.parse_args(argv)
    a.scales = bs.positive_list("--scales", a.scales, 8)
    if not 1 <= a.runs <= 20:
        raise bs.BenchError(f"--runs: expected an integer in [1, 20], got {a.runs}")
    if not 0 < a.memory_share <= 1:
        raise bs.BenchError(f"--memory-share: expected a number in (0, 1], got {a.memory_share}")
    if not re.fullmatch(r"[1-9]\d{0,4}x[1-9]\d{0,4}", a.size):
        raise bs.BenchError(f"--size: expected WIDTHxHEIGHT of positive integers, got {a.size!r}")
    a.isowall = os.path.join(a.build, "bin", "isowall")
    a.peer = os.path.join(a.build, "bench", "peer", "isowall-peer")
    if not os.path.exists(a.isowall):
        raise bs.BenchError(f"--build: {a.isowall} not found; build first (bash scripts/setup.sh)")
    readme = os.path.join(a.data, "README.md")
    if not os.path.exists(readme):
        raise bs.BenchError(f"--data: {readme} not found (is ../shared/data there?)")
    a.suggested = suggested_isovalues(readme)
    names = sorted(f[:-5] for f in os.listdir(a.data) if f.endswith(".nhdr"))
    if a.volumes:
        wanted = a.volumes.split(",")
        bad = [v for v in wanted if v not in names]
        if bad:
            raise bs.BenchError(f"--volumes: {','.join(bad)} not in {a.data} (there: {','.join(names)})")
        names = wanted
    a.names = [n for n in names if n in a.suggested]
    for n in names:
        if n not in a.suggested:
            print(f"{n}: skipped: {readme} suggests no isovalue for it")
    return a


def suggested_isovalues(readme):
    """{name: [(iso, marching-cubes triangles), ...]} from the README's "Suggested isovalues"."""
    out = {}
    with open(readme) as f:
        text = f.read()
    section = text.split("## Suggested isovalues", 1)[-1]
    for m in re.finditer(r"^\| `(\w+)` \| ([-\d.]+) \|[^|]*\|[^|]*\|[^|]*\| ([\d,]+) \|", section, re.M):
        out.setdefault(m.group(1), []).append((float(m.group(2)), int(m.group(3).replace(",", ""))))
    if not out:
        raise bs.BenchError(f"--data: {readme}: no table of suggested isovalues found")
    return out


def available_bytes():
    with open("/proc/meminfo") as f:
        for line in f:
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    raise bs.BenchError("/proc/meminfo: no MemAvailable line")


def thresholds(block):
    """{"c90": s, "c99": s, "c999": s, "tris_c99": n, "fp99": s} of one correctness table."""
    res = {}
    for key, pat in (("c90", "C=1-E >= 90%"), ("c99", "C=1-E >= 99%"), ("c999", "C=1-E >= 99.9%"),
                     ("fp99", "final px >= 99%")):
        m = re.search(r"^  " + re.escape(pat) + r"\s+([\d.]+)\s+\d+\s+[\d.]+%\s+(\d+)", block, re.M)
        res[key] = float(m.group(1)) if m else None
        if key == "c99":
            res["tris_c99"] = int(m.group(2)) if m else None
    return res


def render(a, volume, iso, tmp):
    out = bs.run([a.isowall, "render", "-v", volume, "--iso", f"{iso:g}", "--size", a.size, "-q",
                  "--out", os.path.join(tmp, "image.png"), "--warm-up", "--against-full", "--against-truth"],
                 f"isowall render {volume} --iso {iso:g}")
    own, _, truth = out.partition("correctness (replayed against the full surface at full resolution):")
    if not truth:
        raise bs.BenchError(f"isowall render {volume}: no replay against the full surface in its output")
    own = own.split("correctness (replayed against the final image):", 1)[-1]
    res = {"truth": thresholds(truth), "own": thresholds(own)}
    m = re.search(r"^against the full surface \((\d+) triangles, (\d+) px\): C = ([\d.]+), final px ([\d.]+)%, "
                  r"coverage IoU ([\d.]+)", out, re.M)
    if not m:
        raise bs.BenchError(f"isowall render {volume}: no 'against the full surface' line")
    res.update(full_triangles=int(m.group(1)), covered_px=int(m.group(2)), c_vs_full=float(m.group(3)),
               final_px_vs_full=float(m.group(4)) / 100, iou_vs_full=float(m.group(5)))
    res.update(bs.truth_figures(out, f"isowall render {volume}"))
    m = re.search(r"^drawn: (\d+) of the (\d+) triangles", out, re.M)
    res["drawn"] = int(m.group(1)) if m else None  # the whole frame's, hidden ones included
    m = re.search(r"^progressive: .* in ([\d.]+) s: \d+ groups, (\d+) triangles", out, re.M)
    res["every_ray_s"], res["triangles"] = float(m.group(1)), int(m.group(2))
    return res


def peak_rss_mib(a, volume, iso, tmp, *extra):
    """The peak RSS in MiB that `isowall render` prints, run with only the volume, the isovalue, the
    size and `extra`."""
    out = bs.run([a.isowall, "render", "-v", volume, "--iso", f"{iso:g}", "--size", a.size, "-q",
                  "--out", os.path.join(tmp, "plain.png"), *extra], f"isowall render {volume} --iso {iso:g}")
    m = re.search(r"\| peak RSS ([\d.]+) MiB", out)
    if not m:
        raise bs.BenchError(f"isowall render {volume}: no peak RSS in its timing line")
    return float(m.group(1))


def median_by_own_c99(runs):
    """The median run by time to C = 99% of its own final image; a run that never reached it counts
    as infinitely slow (it stays in the median, never dropped)."""
    key = lambda r: r["own"]["c99"] if r["own"]["c99"] is not None else math.inf  # noqa: E731
    ranked = sorted(runs, key=key)
    return ranked[(len(ranked) - 1) // 2]


def measure(a, name, iso, mc_triangles, scale, tmp):
    a.source = os.path.join(a.data, name + ".nhdr")
    sizes, dtype, _, _ = read_header(a.source)
    voxels = math.prod(round(s * scale) if scale != 1 else s for s in sizes)
    need = 2 * voxels * dtype.itemsize + mc_triangles * scale * scale * BYTES_PER_TRIANGLE
    case = {"volume": name, "iso": iso, "scale": scale, "voxels": voxels, "planned_bytes": need}
    if need > a.memory_share * available_bytes():
        case["skipped"] = (f"needs about {need / 2**30:.1f} GiB, more than {a.memory_share:g} of the "
                           f"{available_bytes() / 2**30:.1f} GiB available")
        print(f"{name} {iso:g} {scale:g}x: skipped: {case['skipped']}", flush=True)
        return case
    volume, out_sizes = bs.scaled_volume(a, scale)
    case["sizes"] = out_sizes
    bs.run([a.isowall, "info", "-v", volume], "isowall info")  # the octree cache, untimed
    runs = [render(a, volume, iso, tmp) for _ in range(a.runs)]
    case["engine"] = dict(median_by_own_c99(runs), runs=runs)
    case["voxel_bytes"] = voxels * dtype.itemsize
    case["rss_mib"] = {"plain": peak_rss_mib(a, volume, iso, tmp),
                       "warm": peak_rss_mib(a, volume, iso, tmp, "--warm-up")}
    if not a.no_peer:
        a.iso = iso
        peers = [bs.peer(a, volume, tmp) for _ in range(a.runs)]
        case["peer"] = bs.median_run(peers, "total_s")
    e = case["engine"]
    print(f"{name} {iso:g} {scale:g}x: C=99% (own) {e['own']['c99']} s, C_T {e['ct']:.5f} (full {e['full_ct']:.5f}), "
          f"gate {'holds' if e['gate'] else 'FAILS'}, peer {case.get('peer', {}).get('total_s')} s, "
          f"peak RSS {case['rss_mib']['plain']:.0f} / {case['rss_mib']['warm']:.0f} MiB (plain / warm)", flush=True)
    return case


def main(argv):
    a = parse_args(argv)
    a.repeat, a.threads = "2", 2  # the peer's steady state on two threads, as bench_scaling.py
    if not a.no_peer and bs.peer_missing(a):
        print(f"peer: skipped: {bs.peer_missing(a)}")
        a.no_peer = True
    os.makedirs(a.out, exist_ok=True)
    import tempfile
    tmp = tempfile.mkdtemp(prefix="isowall-volumes-")
    cases = []
    t0 = time.monotonic()
    try:
        for name in a.names:
            isos = a.suggested[name][:1] if a.isos == "first" else a.suggested[name]
            for iso, tris in isos:
                for scale in a.scales:
                    cases.append(measure(a, name, iso, tris, scale, tmp))
    finally:
        import shutil
        shutil.rmtree(tmp, ignore_errors=True)
    meta = {"size": a.size, "runs": a.runs, "scales": a.scales, "date": time.strftime("%Y-%m-%d %H:%M"),
            "cores": os.cpu_count(), "seconds": round(time.monotonic() - t0),
            "load_average": [round(x, 2) for x in os.getloadavg()]}
    text = report(meta, cases)
    print(text)
    with open(os.path.join(a.out, "volumes.md"), "w") as f:
        f.write(text)
    with open(os.path.join(a.out, "volumes.json"), "w") as f:
        json.dump({"meta": meta, "cases": cases}, f, indent=1)
    for name in a.names:
        plot_volume(meta, [c for c in cases if c["volume"] == name],
                    os.path.join(a.out, f"volumes-{name}.png"))
    print(f"wrote {a.out}/volumes.md, volumes.json, volumes-*.png")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except (bs.BenchError, InputError) as e:
        print(f"bench_volumes: error: {e}", file=sys.stderr)
        sys.exit(1)
