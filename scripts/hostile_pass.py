#!/usr/bin/env python3
"""A hostile pass over isowall's inputs, counted by area (issue "Nothing lies, nothing hangs,
round two"): damaged volume files of every format, hostile option values, damaged wall files,
raw bytes at the server, and signals while `render` writes its image.

Each run is judged by the one failure path: either it succeeds (exit 0, and what it writes is
whole), or it exits non-zero with exactly one line on stderr, `isowall: error: ...`, leaves no
output file, and ends within the time limit. Anything else (a crash by signal, an abort inside a
library, a hang, several lines, a partial file) is a failure, listed with its command.

    python3 scripts/hostile_pass.py [--isowall build/bin/isowall] [--seed 1] [--per-file 12]

Needs ../shared/data for the volume files (the area is skipped without it). Prints a table of
tried / clean / failed per area and the failures; exits 1 when any failed.
"""
import argparse
import os
import random
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIMIT_S = 30


class Tally:
    def __init__(self):
        self.rows = {}
        self.failures = []

    def add(self, area, ok, what):
        tried, clean = self.rows.get(area, (0, 0))
        self.rows[area] = (tried + 1, clean + (1 if ok else 0))
        if not ok:
            self.failures.append(f"{area}: {what}")


def run(cmd, cwd, timeout=LIMIT_S, stdin=subprocess.DEVNULL):
    try:
        p = subprocess.run(cmd, cwd=cwd, stdin=stdin, capture_output=True, text=True,
                           errors="replace", timeout=timeout)
        return p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired:
        return None, "", ""


def judge(rc, err, outputs):
    """(ok, why) by the one failure path."""
    if rc is None:
        return False, "still running after the limit"
    if rc < 0:
        return False, f"ended by signal {-rc}"
    lines = [l for l in err.splitlines() if l.strip()]
    if rc == 0:
        return True, ""
    if len(lines) != 1 or not lines[0].startswith("isowall: error: "):
        return False, f"exit {rc} with stderr {lines[:3]!r}"
    left = [o for o in outputs if Path(o).exists()]
    if left:
        return False, f"exit {rc} but left {left}"
    return True, ""


def mutations(data, rng, count):
    """Damaged copies of `data`: truncations, byte flips in the first 1 KB, and bytes set to
    extremes at random places."""
    out = []
    for frac in (0.0, 0.01, 0.2, 0.5, 0.99):
        out.append(data[: int(len(data) * frac)])
    while len(out) < count:
        b = bytearray(data)
        for _ in range(rng.randint(1, 8)):
            span = min(len(b), 1024) if rng.random() < 0.7 else len(b)
            i = rng.randrange(max(span, 1))
            b[i] = rng.choice([0, 0xFF, 0x7F, 0x80, rng.randrange(256)])
        out.append(bytes(b))
    return out


def volume_area(a, tally, tmp):
    shared = ROOT.parent / "shared" / "data"
    if not shared.exists():
        print("hostile_pass: ../shared/data absent: the volume files area is skipped")
        return
    rng = random.Random(a.seed)
    import gzip
    files = {
        "nifti": ("in.nii", gzip.decompress((shared / "formats" / "engine.nii.gz").read_bytes())[:352 + 4096]),
        "nrrd": ("in.nrrd", (shared / "tooth.nhdr").read_text().replace(
            "tooth.raw", str(shared / "tooth.raw")).encode()),
        "dicom": ("in.dcm", (shared / "formats" / "mrhead_t1_dicom" / "1-060.dcm").read_bytes()),
        "metaimage": ("in.mha", b"ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\n"
                      b"ElementType = MET_UCHAR\nElementSpacing = 1 1 2\n"
                      b"ElementDataFile = LOCAL\n" + bytes(range(64))),
        "tiff": ("in.tif", (ROOT / "fuzz" / "corpus" / "tiff" / "u16_stack.tif").read_bytes()),
        "hdf5": ("in.h5", (ROOT / "fuzz" / "corpus" / "hdf5" / "u8_chunked_or_contiguous.h5").read_bytes()),
    }
    # The NIfTI copy holds fewer voxels than its header: fix the header to 16x16x16.
    nii = bytearray(files["nifti"][1])
    struct.pack_into("<8h", nii, 40, 3, 16, 16, 16, 1, 1, 1, 1)
    files["nifti"] = ("in.nii", bytes(nii))
    for fmt, (name, data) in files.items():
        for k, variant in enumerate(mutations(data, rng, a.per_file)):
            d = tmp / f"{fmt}{k}"
            d.mkdir()
            path = d / name
            if fmt == "dicom":  # a series of two: the damaged file and a good one
                path = d / "series"
                path.mkdir()
                (path / "a.dcm").write_bytes(variant)
                shutil.copy(shared / "formats" / "mrhead_t1_dicom" / "1-061.dcm", path / "b.dcm")
            else:
                path.write_bytes(variant)
            out = d / "out.png"
            rc, _, err = run([a.isowall, "render", "--no-cache", "-v", str(path), "--size",
                              "32x24", "--no-measure", "--out", str(out)], d)
            if rc != 0 or err:
                ok, why = judge(rc, err, [out])
            else:
                ok, why = out.exists() and out.stat().st_size > 0, "exit 0 without an image"
            # An iso outside the range is an option error, not a fault of the file.
            if rc == 2 and "--iso" in err:
                ok, why = True, ""
            tally.add(f"volume: {fmt}", ok, f"{why}: variant {k} in {d}")


def options_area(a, tally, tmp):
    values = {
        "--size": ["0x0", "-5x5", "99999x2", "1e3x100", "axb", "", "32x", "32x24x1", "4294967297x2"],
        "--iso": ["nan", "inf", "-inf", "1e400", "0x10", "", "5,5"],
        "--zoom": ["0", "-1", "nan", "1e-300", "1e300"],
        "--orbit": ["nan 0", "0", "1e308 1e308", "inf 0"],
        "--threads": ["-1", "1e9", "2.5", "99999"],
        "--out": ["", "/", "/proc/x.png", "no_such_dir/x.png", "x.unknownext", "x" * 300 + ".png"],
        "--order": ["", "nope", "dynamic;rm"],
    }
    for opt, vals in values.items():
        for v in vals:
            d = Path(tempfile.mkdtemp(dir=tmp))
            args = [a.isowall, "render", "--size", "32x24", "--no-measure", "--out",
                    str(d / "o.png")]
            args += [opt] + v.split(" ") if opt == "--orbit" else [opt, v]
            rc, _, err = run(args, d)
            ok, why = judge(rc, err, [d / "o.png"] if opt != "--out" else [])
            if rc == 0 and opt != "--out":
                ok, why = False, "accepted"
            tally.add("options: render", ok, f"{why}: {opt} {v!r}")


def wall_area(a, tally, tmp):
    good = 'tiles = [2, 2]\ntile_size_px = [160, 120]\n'
    bad = [
        "tiles = [0, 2]\n", "tiles = [2]\n", "tiles = [2, 2]\ntile_size_px = [-1, 5]\n",
        "tiles = [2, 2]\ntile_size_px = [1e9, 1]\n", "tiles = [1e400, 1]\n", "tiles = 'x'\n",
        "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[\n", "tiles = [2, 2]\nbezel_px = [nan, 0]\n",
        good + "tile_size_px = [160, 120]\n", "\x00\xff\xfe", good + "bezel_px = [-500, 0]\n",
        "tiles = [65536, 65536]\ntile_size_px = [32768, 32768]\n",
    ]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for k, text in enumerate(bad):
        d = Path(tempfile.mkdtemp(dir=tmp))
        (d / "w.toml").write_text(text, errors="surrogateescape")
        cmd = ["mpirun", "--oversubscribe", "-np", "5", a.isowall, "wall", "--wall",
               str(d / "w.toml"), "--out", str(d / "m.png"), "--timeout", "10"]
        try:
            p = subprocess.run(cmd, cwd=d, capture_output=True, text=True, errors="replace",
                               timeout=90, env=env, stdin=subprocess.DEVNULL)
            rc, err = p.returncode, p.stderr
        except subprocess.TimeoutExpired:
            rc, err = None, ""
        errors = [l for l in err.splitlines() if l.startswith("isowall: error: ")]
        ok = rc not in (None, 0) and len(errors) >= 1 and not (d / "m.png").exists()
        tally.add("wall files", ok, f"exit {rc}, {len(errors)} error lines: {text[:40]!r}")


def server_area(a, tally, tmp):
    d = Path(tempfile.mkdtemp(dir=tmp))
    srv = subprocess.Popen([a.isowall, "serve", "--port", "0", "--idle-timeout", "5"], cwd=d,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    port = None
    end = time.time() + 60
    while time.time() < end and port is None:
        line = srv.stdout.readline()
        if "listening on" in line:
            port = int(line.rsplit(":", 1)[1])
    if port is None:
        tally.add("server", False, "serve did not start")
        srv.kill()
        return
    rng = random.Random(a.seed)
    header = lambda t, n: b"IWVP" + struct.pack("<HHI", 1, t, n)
    payloads = [b"", b"\x00" * 12, header(1, 0xFFFFFFFF), header(99, 0), header(1, 3) + b"\x01",
                b"GET / HTTP/1.1\r\n\r\n", header(3, 8) + b"\x01" * 8]
    payloads += [bytes(rng.randrange(256) for _ in range(rng.randrange(1, 200))) for _ in range(20)]
    for k, p in enumerate(payloads):
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
                s.sendall(p)
                s.shutdown(socket.SHUT_WR)
                s.settimeout(10)
                while s.recv(4096):
                    pass
            alive = srv.poll() is None
        except (OSError, socket.timeout) as e:
            alive = srv.poll() is None and not isinstance(e, socket.timeout)
        tally.add("server: raw bytes", alive, f"payload {k} ({p[:16]!r}) left the server "
                  f"{'alive' if srv.poll() is None else 'dead'}")
    # A good client after all of it.
    rc, _, err = run([a.isowall, "view", "--connect", f"127.0.0.1:{port}", "--size", "64x48",
                      "--out", str(d / "v.png")], d)
    tally.add("server: raw bytes", rc == 0 and (d / "v.png").exists(),
              f"a good client after the payloads: exit {rc} {err[-200:]}")
    srv.send_signal(signal.SIGINT)
    try:
        srv.wait(10)
    except subprocess.TimeoutExpired:
        srv.kill()
        tally.add("server: raw bytes", False, "serve did not end on SIGINT")


def signal_area(a, tally, tmp):
    rng = random.Random(a.seed)
    for k in range(a.per_file):
        d = Path(tempfile.mkdtemp(dir=tmp))
        out = d / "o.png"
        p = subprocess.Popen([a.isowall, "render", "--size", "1600x1200", "--out", str(out)],
                             cwd=d, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(rng.uniform(0.2, 3.0))
        sig = rng.choice([signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
        p.send_signal(sig)
        try:
            _, err = p.communicate(timeout=LIMIT_S)
            rc = p.returncode
        except subprocess.TimeoutExpired:
            p.kill()
            rc, err = None, ""
        left = sorted(x.name for x in d.iterdir())
        if rc == 0:  # it finished before the signal: the image must be whole
            ok = out.exists() and out.read_bytes()[-8:-4] == b"IEND" and left == ["o.png"]
        else:
            ok = rc is not None and left == []
        tally.add("signals: render", ok, f"{sig.name}: exit {rc}, left {left}")


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--isowall", default=str(ROOT / "build" / "bin" / "isowall"))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--per-file", type=int, default=12)
    ap.add_argument("--areas", default="volume,options,wall,server,signals")
    a = ap.parse_args(argv)
    tally = Tally()
    with tempfile.TemporaryDirectory(prefix="isowall-hostile-") as t:
        tmp = Path(t)
        areas = {"volume": volume_area, "options": options_area, "wall": wall_area,
                 "server": server_area, "signals": signal_area}
        for name in a.areas.split(","):
            areas[name](a, tally, tmp)
    print(f"{'area':24} {'tried':>6} {'clean':>6} {'failed':>7}")
    for area, (tried, clean) in tally.rows.items():
        print(f"{area:24} {tried:6d} {clean:6d} {tried - clean:7d}")
    tried = sum(t for t, _ in tally.rows.values())
    clean = sum(c for _, c in tally.rows.values())
    print(f"{'all':24} {tried:6d} {clean:6d} {tried - clean:7d}")
    for f in tally.failures:
        print("FAILED", f)
    return 1 if tally.failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
