#!/usr/bin/python3
"""Volumes past memory: the same volume read from its file and from a store made by
`isowall import`, with the default `isowall render` (1600x1200, front view), on a cold page
cache (as root: `sync; echo 3 > /proc/sys/vm/drop_caches` before each run) and warm: time to the
first picture, to C = 99% and to 99% of the final pixels, the peak resident memory, and what the
store read. The store is read once at the default memory limit and once at --limit (default 1/8
of the volume's bytes). The import is timed cold against the disk's sequential read of the same
source file, in the same run.

Usage: /usr/bin/python3 scripts/bench_store.py [--volume build/data/cthead_1024x1024x452.nhdr]
           [--iso 600] [--limit 1/8 | 256M] [--runs 2] [--size 1600x1200] [--no-cold]
           [--no-file] [--store STORE] [--reference PNG] [--disk-mbps N] [--build build]
           [--out out/bench-store]

--no-file leaves out the file rows (a volume past this machine's memory cannot be read whole);
--store uses a store made before instead of importing (no import figures); --reference compares
the store's picture under the limit with a picture made elsewhere (e.g. the in-memory render of a
smaller copy, same view and size): coverage IoU and the share of pixels within 1/255.

--disk-mbps N emulates a disk that reads N MB/s (root: a cgroup's block-I/O read throttle on the
disk that holds the volume, for this script and every program it runs, the disk-rate measure
included). A virtual disk whose host caches it reads at 0.4-3.9 GB/s from one run to the next;
a workstation's NVMe reads 2-3 GB/s, a SATA SSD 0.5 GB/s, a cluster's file system per node less.
The figures of every path are taken at the same rate, so their ratios are those of that disk.

Prints one table (markdown), the import line and the issue's ratios, and writes them to
OUT/store.md. Without root, or with --no-cold, the cold rows are skipped and say so. Errors: one
line naming the option or the program, exit 1.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print(f"bench_store: error: {msg}", file=sys.stderr)
    sys.exit(1)


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 1)[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--volume", default=os.path.join(ROOT, "build/data/cthead_1024x1024x452.nhdr"))
    ap.add_argument("--iso", type=float, default=600.0)
    ap.add_argument("--limit", default="1/8")
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--size", default="1600x1200")
    ap.add_argument("--no-cold", action="store_true", help="warm runs only (no drop_caches)")
    ap.add_argument("--no-file", action="store_true", help="no rows read from the file")
    ap.add_argument("--store", help="a store made before (skips the import)")
    ap.add_argument("--reference", help="a PNG to compare the store's picture with")
    ap.add_argument("--disk-mbps", type=float, help="emulate a disk that reads this many MB/s")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out/bench-store"))
    try:
        a = ap.parse_args(argv)
    except SystemExit as e:
        if e.code == 0:
            raise
        sys.exit(1)
    if a.runs < 1:
        fail(f"--runs: expected at least 1, got {a.runs}")
    if a.disk_mbps is not None and a.disk_mbps <= 0:
        fail(f"--disk-mbps: expected a rate above 0, got {a.disk_mbps:g}")
    if a.disk_mbps and os.geteuid() != 0:
        fail("--disk-mbps: needs root (a cgroup's block-I/O throttle)")
    if not os.path.exists(a.volume):
        fail(f"--volume: {a.volume}: no such file (scripts/resample_volume.py makes the copies)")
    if a.store and not os.path.isdir(a.store):
        fail(f"--store: {a.store}: no such folder")
    if a.reference and not os.path.exists(a.reference):
        fail(f"--reference: {a.reference}: no such file")
    if a.reference:
        try:  # checked now, not after the runs: a python3 without them would lose every figure
            import numpy  # noqa: F401
            import matplotlib.image  # noqa: F401
        except ImportError as e:
            fail(f"--reference: needs numpy and matplotlib ({e.name} is missing from "
                 f"{sys.executable}; run /usr/bin/python3, Debian's python3-matplotlib)")
    m = re.fullmatch(r"1/([0-9]+)", a.limit)
    if m:
        if int(m.group(1)) < 1:
            fail(f"--limit: expected 1/N with N >= 1 or a size such as 256M, got {a.limit}")
        a.limit = "%dM" % max(16, source_bytes(a.volume) // int(m.group(1)) // (1 << 20))
    a.binary = os.path.join(a.build, "bin", "isowall")
    if not os.access(a.binary, os.X_OK):
        fail(f"--build: {a.binary}: not built (run scripts/setup.sh)")
    return a


def whole_disk(dev):
    """'major:minor' of the disk that holds device number `dev` (a partition's parent: the
    throttle applies to whole disks)."""
    node = os.path.realpath(f"/sys/dev/block/{os.major(dev)}:{os.minor(dev)}")
    if os.path.exists(os.path.join(node, "partition")):
        node = os.path.dirname(node)
    with open(os.path.join(node, "dev")) as f:
        return f.read().strip()


def throttle_reads(paths, mbps):
    """Moves this process (and so every program it starts) into a cgroup whose reads from the
    disks holding `paths` are throttled to `mbps` MB/s each; returns the cgroup's folder."""
    disks = sorted({whole_disk(os.stat(p).st_dev) for p in paths})
    rate = int(mbps * 1e6)
    for root, knob, form in (("/sys/fs/cgroup/blkio", "blkio.throttle.read_bps_device", "{} {}"),
                             ("/sys/fs/cgroup", "io.max", "{} rbps={}")):
        if os.path.exists(os.path.join(root, "cgroup.procs")) and (
                root != "/sys/fs/cgroup" or os.path.exists(os.path.join(root, "cgroup.controllers"))):
            group = os.path.join(root, f"isowall-bench-{os.getpid()}")
            os.makedirs(group, exist_ok=True)
            try:
                for disk in disks:
                    with open(os.path.join(group, knob), "w") as f:
                        f.write(form.format(disk, rate) + "\n")
                with open(os.path.join(group, "cgroup.procs"), "w") as f:
                    f.write(str(os.getpid()))
            except OSError as e:
                fail(f"--disk-mbps: {os.path.join(group, knob)}: {e.strerror}")
            return group
    fail("--disk-mbps: no block-I/O cgroup here (neither cgroup v1 blkio nor v2 io)")


def leave_cgroup(group):
    with open(os.path.join(os.path.dirname(group), "cgroup.procs"), "w") as f:
        f.write(str(os.getpid()))
    os.rmdir(group)


def drop_caches():
    subprocess.run(["sync"], check=True)
    with open("/proc/sys/vm/drop_caches", "w") as f:
        f.write("3\n")


def data_file(volume):
    """The file that holds the voxels: a detached NRRD header's data file, else the volume."""
    if volume.endswith(".nhdr"):
        with open(volume, encoding="latin-1") as f:
            for line in f:
                if line.lower().startswith("data file:"):
                    return os.path.join(os.path.dirname(volume), line.split(":", 1)[1].strip())
    return volume


def source_bytes(volume):
    return os.path.getsize(data_file(volume))


def disk_read_rate(path, most=8 << 30):
    """MB/s of one cold sequential read of `path` (at most `most` bytes), in 16 MiB blocks."""
    drop_caches()
    fd = os.open(path, os.O_RDONLY)
    got = 0
    t0 = time.monotonic()
    try:
        while got < most:
            n = len(os.read(fd, 16 << 20))
            if n == 0:
                break
            got += n
    finally:
        os.close(fd)
    return got / (time.monotonic() - t0) / 1e6


def compare_png(a_path, b_path):
    """(coverage IoU, share of the covered pixels within 1/255 in every channel) of two PNGs of
    one size; covered: not the black background."""
    import numpy as np
    import matplotlib.image as mpimg
    a = (mpimg.imread(a_path)[..., :3] * 255).round()
    b = (mpimg.imread(b_path)[..., :3] * 255).round()
    if a.shape != b.shape:
        fail(f"--reference: {b_path} is {b.shape[1]}x{b.shape[0]}, the render {a.shape[1]}x{a.shape[0]}")
    ca, cb = a.max(axis=2) > 0, b.max(axis=2) > 0
    union = (ca | cb).sum()
    iou = (ca & cb).sum() / union if union else 1.0
    close = (np.abs(a - b).max(axis=2) <= 1) & (ca | cb)
    return iou, close.sum() / union if union else 1.0


def number(pattern, text, default=None):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else default


def render(a, volume, extra, cold, cache_dir):
    if cold:
        drop_caches()
    png = os.path.join(a.out, "render.png")
    cmd = [a.binary, "render", "--volume", volume, "--iso", str(a.iso), "--out", png, "--size", a.size,
           "--cache-dir", cache_dir] + extra
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    if p.returncode != 0:
        fail(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()[:300]}")
    out = p.stdout
    return {
        "first": number(r"first picture: ([0-9.]+) s after the command began", out),
        "c99": number(r"C=1-E >= 99%\s+([0-9.]+)", out),
        "px99": number(r"final px >= 99%\s+([0-9.]+)", out),
        "frame": number(r"progressive frame ([0-9.]+) s", out),
        "rss": number(r"peak RSS ([0-9.]+) MiB", out),
        "read": number(r"bricks: \d+ read \(([0-9.]+) MiB from disk\)", out),
        "peak": number(r"peak ([0-9.]+) MiB of the", out),
        "command": wall,
    }


def median(values):
    v = sorted(x for x in values if x is not None)
    return v[len(v) // 2] if v else None


def import_store(a, store, cache_dir, cold_ok):
    """Imports a.volume (cold when allowed); (seconds, the import's line, disk MB/s or None).
    The disk is read once before and once after the import, and the faster read counts (a
    virtual disk's speed varies with what its host holds), so the ratio is not flattered."""
    disk = disk_read_rate(data_file(a.volume)) if cold_ok else None
    if os.path.isdir(store):
        shutil.rmtree(store)  # removing a store is not importing one
    if cold_ok:
        drop_caches()
    t0 = time.monotonic()
    p = subprocess.run([a.binary, "import", a.volume, "--out", store, "-q",
                        "--cache-dir", cache_dir], capture_output=True, text=True)
    if p.returncode != 0:
        fail(f"import: exit {p.returncode}: {p.stderr.strip()[:300]}")
    seconds = time.monotonic() - t0
    if disk:
        disk = max(disk, disk_read_rate(data_file(a.volume)))
    return seconds, p.stdout.strip(), disk


def measure_cases(a, cases, cold_ok, cache_dir):
    rows = []
    for label, volume, extra in cases:
        render(a, volume, extra, False, cache_dir)  # the octree cache, the program's own pages
        for cold in (True, False):
            if cold and not cold_ok:
                rows.append((label, "cold", None))
                continue
            runs = [render(a, volume, extra, cold, cache_dir) for _ in range(a.runs)]
            rows.append((label, "cold" if cold else "warm",
                         {k: median([r[k] for r in runs]) for k in runs[0]}))
    return rows


def table(a, rows):
    fmt = lambda v, f="%.3f": "-" if v is None else f % v  # noqa: E731
    lines = ["| source | cache | first picture | C = 99% | 99% of final px | whole command "
             "| peak RSS | store read from disk | store peak |",
             "|---|---|---|---|---|---|---|---|---|"]
    for label, cache, r in rows:
        if r is None:
            why = "--no-cold" if a.no_cold else "not root (no drop_caches)"
            lines.append(f"| {label} | {cache} | skipped: {why} | | | | | | |")
            continue
        lines.append(f"| {label} | {cache} | {fmt(r['first'])} | {fmt(r['c99'])} "
                     f"| {fmt(r['px99'])} | {fmt(r['command'], '%.2f')} | {fmt(r['rss'], '%.0f')} "
                     f"| {fmt(r['read'], '%.1f')} | {fmt(r['peak'], '%.1f')} |")
    return lines


def ratios(a, rows):
    """The issue's targets, from the rows: warm C = 99% and cold first picture, store under the
    limit against the file."""
    get = {(label, cache): r for label, cache, r in rows}
    limited = f"store, --memory-limit {a.limit}"
    out = []
    for cache, key, target, what in (("warm", "c99", 1.5, "time to C = 99%"),
                                      ("cold", "first", 0.2, "time to the first picture")):
        f, s = get.get(("file", cache)), get.get((limited, cache))
        if f and s and f[key] and s[key]:
            ratio = s[key] / f[key]
            out.append(f"{cache} {what}: store under {a.limit} / file = {ratio:.2f} "
                       f"(target at most {target}: {'holds' if ratio <= target else 'missed'})")
    return out


def main(argv):
    a = parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    cache_dir = os.path.join(a.out, "octree-cache")
    name = os.path.basename(a.volume).split(".")[0]
    cold_ok = os.geteuid() == 0 and not a.no_cold
    notes = []
    group = throttle_reads([data_file(a.volume), a.out], a.disk_mbps) if a.disk_mbps else None
    try:
        run(a, name, cache_dir, cold_ok, notes)
    finally:
        if group:
            leave_cgroup(group)


def run(a, name, cache_dir, cold_ok, notes):
    store = a.store
    if not store:
        store = os.path.join(a.out, name + ".zarr")
        import_s, line, disk = import_store(a, store, cache_dir, cold_ok)
        print(line)
        rate = source_bytes(a.volume) / import_s / 1e6
        note = f"Import took {import_s:.1f} s: {rate:.0f} MB/s of the source"
        if disk:
            note += (f"; the disk reads the source file at {disk:.0f} MB/s (cold, sequential, the "
                     f"faster of a read before and one after), "
                     f"ratio {rate / disk:.2f} (target at least 0.5: "
                     f"{'holds' if rate >= 0.5 * disk else 'missed'})")
        notes.append(note + ".")
    cases = [] if a.no_file else [("file", a.volume, [])]
    cases += [("store, default limit", store, []),
              (f"store, --memory-limit {a.limit}", store, ["--memory-limit", a.limit])]
    rows = measure_cases(a, cases, cold_ok, cache_dir)
    if a.reference:
        iou, close = compare_png(os.path.join(a.out, "render.png"), a.reference)
        notes.append(f"The picture under {a.limit} against {a.reference}: coverage IoU {iou:.5f}, "
                     f"{100 * close:.2f}% of pixels within 1/255.")
    lines = [f"# {name}: file against store, default render ({a.size}), iso {a.iso:g}", ""]
    if a.disk_mbps:
        lines += [f"Disk emulated at {a.disk_mbps:g} MB/s (a block-I/O read throttle on every "
                  "program this benchmark runs).", ""]
    lines += [n + "\n" for n in notes]
    lines += [f"Medians of {a.runs} runs; seconds, MiB.", ""] + table(a, rows) + [""]
    lines += ratios(a, rows)
    text = "\n".join(lines) + "\n"
    print(text)
    with open(os.path.join(a.out, "store.md"), "w") as f:
        f.write(text)
    print(f"wrote {os.path.join(a.out, 'store.md')}")


if __name__ == "__main__":
    main(sys.argv[1:])
