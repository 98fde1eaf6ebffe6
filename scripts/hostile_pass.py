#!/usr/bin/env python3
"""A hostile pass over isowall's inputs, counted by area: damaged volume files of every format,
headers that lie (offsets, scalings, declared sizes), damaged stores, imports raced, signalled and
forced, hostile option values, damaged wall files, raw bytes at the server, pages that reach the
server by a foreign name, and signals while `render` writes its image.

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


def run_and_signal(cmd, cwd, rng, lo, hi):
    """Starts `cmd`, sends it SIGINT, SIGTERM or SIGHUP after a random lo..hi s; (signal, exit
    status, None past the limit)."""
    p = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         text=True)
    time.sleep(rng.uniform(lo, hi))
    sig = rng.choice([signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
    p.send_signal(sig)
    try:
        p.communicate(timeout=LIMIT_S)
        return sig, p.returncode
    except subprocess.TimeoutExpired:
        p.kill()
        p.communicate()
        return sig, None


def whole_png(path):
    data = Path(path).read_bytes() if Path(path).exists() else b""
    return data[:8] == b"\x89PNG\r\n\x1a\n" and data[-8:-4] == b"IEND"


def judge(rc, err, outputs):
    """(ok, why) by the one failure path; on exit 0 every PNG among `outputs` must be whole."""
    if rc is None:
        return False, "still running after the limit"
    if rc < 0:
        return False, f"ended by signal {-rc}"
    lines = [l for l in err.splitlines() if l.strip()]
    if rc == 0:
        broken = [o for o in outputs if str(o).endswith(".png") and not whole_png(o)]
        return (False, f"exit 0 but {broken} not a whole PNG") if broken else (True, "")
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
            ok, why = judge(rc, err, [out])
            if rc == 0 and err.strip():
                ok, why = False, f"exit 0 with stderr {err.splitlines()[:2]!r}"
            tally.add(f"volume: {fmt}", ok, f"{why}: variant {k} in {d}")


def nifti_bytes(offset=352.0, slope=0.0, inter=0.0, dims=(16, 16, 16), voxels=True):
    """A NIfTI-1 single file of uint8 voxels with the header fields given."""
    h = bytearray(348)
    struct.pack_into("<i", h, 0, 348)
    struct.pack_into("<8h", h, 40, 3, *dims, 1, 1, 1, 1)
    struct.pack_into("<hh", h, 70, 2, 8)  # DT_UINT8, 8 bits
    struct.pack_into("<8f", h, 76, 1, 1, 1, 1, 1, 1, 1, 1)
    struct.pack_into("<f", h, 108, offset)
    struct.pack_into("<ff", h, 112, slope, inter)
    h[344:348] = b"n+1\0"
    n = dims[0] * dims[1] * dims[2] if voxels else 0
    return bytes(h) + b"\0\0\0\0" + bytes((i * 7) % 251 for i in range(n))


def headers_area(a, tally, tmp):
    """Headers that lie: NIfTI offsets and scalings, declared sizes past the bytes (plain and
    gzip), TIFF stacks cut at every few bytes. Each must read or be refused in one line."""
    import gzip
    cases = []
    for off in (float("nan"), float("inf"), -1.0, 1e10, 100.0, 352.5, 353.0, 1e30):
        cases.append((f"vox_offset {off}", "in.nii", nifti_bytes(offset=off)))
    for slope, inter in ((float("nan"), 0), (float("inf"), 0), (1e38, 0), (-1e38, 5), (1, 3e38),
                         (1e-45, 0), (0, float("nan")), (1e38, 1e38)):
        cases.append((f"scl {slope} {inter}", "in.nii", nifti_bytes(slope=slope, inter=inter)))
    cases.append(("claims 4096^3, holds none", "in.nii",
                  nifti_bytes(dims=(4096, 4096, 4096), voxels=False)))
    cases.append(("gzip claims 4096x4096x512", "in.nii.gz",
                  gzip.compress(nifti_bytes(dims=(4096, 4096, 512), voxels=False))))
    tiff = (ROOT / "fuzz" / "corpus" / "tiff" / "u16_stack.tif").read_bytes()
    for cut in range(8, len(tiff), max(1, len(tiff) // 40)):
        cases.append((f"tiff cut at {cut} of {len(tiff)}", "in.tif", tiff[:cut]))
    for k, (what, name, data) in enumerate(cases):
        d = tmp / f"header{k}"
        d.mkdir()
        (d / name).write_bytes(data)
        out = d / "o.png"
        rc, _, err = run([a.isowall, "render", "--no-cache", "-v", str(d / name), "--size",
                          "32x24", "--no-measure", "--out", str(out)], d)
        ok, why = judge(rc, err, [out])
        tally.add("readers: lying headers", ok, f"{why}: {what} in {d}")


def raw_volume(d, n=48, ball=True):
    """A uint8 raw volume (a ball, or for large ones a repeating ramp) and the options that read
    it."""
    c = (n - 1) / 2
    data = bytes(min(255, int(4 * ((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2) ** 0.5))
                 for z in range(n) for y in range(n) for x in range(n)) if ball else \
        (bytes(range(251)) * (n ** 3 // 251 + 1))[: n ** 3]
    (d / "ball.raw").write_bytes(data)
    return ["ball.raw", "--dims", str(n), str(n), str(n), "--type", "uint8"]


def stores_area(a, tally, tmp):
    """A store damaged every way a disk or a hand can: chunks cut, flipped, swapped for a FIFO or
    a folder, removed; metadata cut or made nonsense. `render` of it must end in one line."""
    base = tmp / "store_base"
    base.mkdir()
    src = raw_volume(base, 96)
    rc, _, err = run([a.isowall, "import", *src, "--out", "s.zarr", "-q", "--levels", "1"], base)
    if rc != 0:
        tally.add("stores: damaged", False, f"the import failed: {err[-200:]}")
        return
    rng = random.Random(a.seed)
    chunks = sorted(p for p in (base / "s.zarr" / "0").rglob("*") if p.is_file()
                    and p.name != ".zarray")
    damages = ["cut", "flip", "fifo", "folder", "remove", "empty"] * 3
    metas = [".zattrs", ".zgroup", "0/.zarray"]
    for k, dmg in enumerate(damages + [f"meta:{m}" for m in metas] * 2):
        d = tmp / f"store{k}"
        shutil.copytree(base, d, symlinks=True)
        s = d / "s.zarr"
        if dmg.startswith("meta:"):
            f = s / dmg[5:]
            text = f.read_bytes()
            f.write_bytes(text[: rng.randrange(len(text))] if k % 2 else
                          text.replace(b"3", b"9").replace(b"]", b""))
        else:
            f = d / "s.zarr" / rng.choice(chunks).relative_to(base / "s.zarr")
            if dmg == "cut":
                f.write_bytes(f.read_bytes()[: rng.randrange(max(1, f.stat().st_size))])
            elif dmg == "flip":
                b = bytearray(f.read_bytes())
                b[rng.randrange(len(b))] ^= 0xFF
                f.write_bytes(bytes(b))
            elif dmg == "fifo":
                f.unlink()
                os.mkfifo(f)
            elif dmg == "folder":
                f.unlink()
                f.mkdir()
            elif dmg == "remove":
                f.unlink()
            else:
                f.write_bytes(b"")
        out = d / "o.png"
        rc, _, err = run([a.isowall, "render", "--volume", "s.zarr", "--no-cache", "--iso", "100",
                          "--size", "48x36", "--no-measure", "--memory-limit", "64M", "--out",
                          str(out)], d)
        ok, why = judge(rc, err, [out])
        # A missing chunk is refused at open; other damage only where a frame reads it.
        if rc == 0 and dmg == "remove":
            ok, why = False, "a store missing a chunk drew a picture"
        tally.add("stores: damaged", ok, f"{why}: {dmg} in {d}")


def imports_area(a, tally, tmp):
    """Imports raced, signalled and forced: two into one store at once (one lands, whole, the other
    refused or after it), SIGTERM at a random moment (no temporary left), --force onto folders
    that are not isowall's stores (every file kept)."""
    rng = random.Random(a.seed)
    for k in range(max(2, a.per_file // 3)):
        d = Path(tempfile.mkdtemp(dir=tmp))
        src = raw_volume(d, 160)
        cmd = [a.isowall, "import", *src, "--out", "s.zarr", "-q"]
        procs = [subprocess.Popen(cmd, cwd=d, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                  text=True) for _ in range(2)]
        results = []
        for p in procs:
            try:
                _, err = p.communicate(timeout=LIMIT_S)
                results.append((p.returncode, err))
            except subprocess.TimeoutExpired:
                p.kill()
                results.append((None, ""))
        judged = [judge(rc, err, []) for rc, err in results]
        landed = [rc for rc, _ in results if rc == 0]
        info_rc, info, _ = run([a.isowall, "info", "--volume", "s.zarr"], d)
        left = sorted(x.name for x in d.iterdir() if x.name.startswith("."))
        ok = all(j[0] for j in judged) and landed and info_rc == 0 and "160x160x160" in info \
            and not left
        tally.add("imports: two at once", ok, f"exits {[r for r, _ in results]}, "
                  f"info exit {info_rc}, left {left}: {[j[1] for j in judged if not j[0]]} in {d}")
    for k in range(a.per_file):
        d = Path(tempfile.mkdtemp(dir=tmp))
        src = raw_volume(d, 512, ball=False)  # 128 MiB: an import of a second or so
        sig, rc = run_and_signal([a.isowall, "import", *src, "--out", "s.zarr", "-q"], d, rng,
                                 0.0, 1.0)
        left = sorted(x.name for x in d.iterdir() if x.name != "ball.raw")
        if rc == 0:  # it finished first: the store must be whole
            ok = left == ["s.zarr"] and run([a.isowall, "info", "--volume", "s.zarr"], d)[0] == 0
        else:
            ok = rc == -sig and left == []
        tally.add("imports: signals", ok, f"{sig.name}: exit {rc}, left {left} in {d}")
    lookalikes = {
        "empty json": {".zattrs": "{}", "0/.zarray": "{}", "thesis.tex": "mine"},
        "not json": {".zattrs": "\x00\xff", "0/.zarray": "[", "notes.txt": "mine"},
        "a file": None,
    }
    for what, files in lookalikes.items():
        d = Path(tempfile.mkdtemp(dir=tmp))
        src = raw_volume(d, 32)
        target = d / "s.zarr"
        if files is None:
            target.write_text("mine")
        else:
            for name, text in files.items():
                (target / name).parent.mkdir(parents=True, exist_ok=True)
                (target / name).write_text(text, errors="surrogateescape")
        before = sorted(str(x.relative_to(d)) for x in target.rglob("*")) if files else ["s.zarr"]
        rc, _, err = run([a.isowall, "import", *src, "--out", "s.zarr", "--force", "-q"], d)
        after = sorted(str(x.relative_to(d)) for x in target.rglob("*")) if files else \
            (["s.zarr"] if target.is_file() else [])
        ok, why = judge(rc, err, [])
        ok = ok and rc != 0 and before == after
        tally.add("imports: --force", ok, f"{why}: {what}: exit {rc}, files {after} in {d}")
    for out in ["", "/", "/proc/s.zarr", "no_such_dir/s.zarr", "ball.raw"]:
        d = Path(tempfile.mkdtemp(dir=tmp))
        src = raw_volume(d, 32)
        rc, _, err = run([a.isowall, "import", *src, "--out", out, "-q"], d)
        ok, why = judge(rc, err, [])
        ok = ok and rc != 0 and (d / "ball.raw").stat().st_size == 32 ** 3
        tally.add("imports: --out", ok, f"{why}: --out {out!r}: exit {rc}")


def page_area(a, tally, tmp):
    """The page and its WebSocket reached by a name the server does not serve (DNS rebinding):
    refused with 403; by its address, localhost or --allow-host: served."""
    d = Path(tempfile.mkdtemp(dir=tmp))
    srv = subprocess.Popen([a.isowall, "serve", "--port", "0", "--http", "0", "--allow-host",
                            "wall.example"], cwd=d, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    http = None
    for _ in range(200):
        line = srv.stdout.readline()
        if not line:
            break
        if "page at" in line:
            http = int(line.split("://", 1)[1].split("/", 1)[0].rsplit(":", 1)[1])
            break
    if http is None:
        tally.add("page: Host", False, "serve --http did not start")
        srv.kill()
        return
    ws = ("Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
          "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n")
    cases = []
    for host in ["evil.example", "evil.example:%d" % http, "127.0.0.1.evil.example",
                 "localhost.evil.example", "", "[::1]evil", "x" * 300]:
        for path, extra in (("/", ""), ("/ws", ws)):
            cases.append((host, path, extra, False))
            cases.append((host, path, extra + f"Origin: http://{host}\r\n", False))
    for host in ["127.0.0.1:%d" % http, "localhost:%d" % http, "wall.example:%d" % http,
                 "app.localhost"]:
        cases.append((host, "/", "", True))
    for host, path, extra, served in cases:
        req = f"GET {path} HTTP/1.1\r\nHost: {host}\r\n{extra}\r\n".encode()
        status = None
        try:
            with socket.create_connection(("127.0.0.1", http), timeout=10) as s:
                s.sendall(req)
                head = s.recv(64).decode(errors="replace")
                status = int(head.split()[1]) if head.startswith("HTTP/") else None
        except (OSError, ValueError, IndexError):
            status = None
        ok = (status in (200, 101)) if served else status in (400, 403)
        tally.add("page: Host", ok, f"Host {host[:40]!r} {path}: status {status}")
    srv.send_signal(signal.SIGTERM)
    try:
        srv.wait(10)
        tally.add("page: Host", srv.returncode == -signal.SIGTERM,
                  f"serve ended with {srv.returncode} on SIGTERM, not by the signal")
    except subprocess.TimeoutExpired:
        srv.kill()
        tally.add("page: Host", False, "serve did not end on SIGTERM")


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
        ok = rc not in (None, 0) and len(errors) == 1 and not (d / "m.png").exists()
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
        sig, rc = run_and_signal([a.isowall, "render", "--size", "1600x1200", "--out", str(out)],
                                 d, rng, 0.2, 3.0)
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
    ap.add_argument("--areas",
                    default="volume,headers,stores,imports,options,wall,server,page,signals")
    a = ap.parse_args(argv)
    tally = Tally()
    with tempfile.TemporaryDirectory(prefix="isowall-hostile-") as t:
        tmp = Path(t)
        areas = {"volume": volume_area, "headers": headers_area, "stores": stores_area,
                 "imports": imports_area, "options": options_area, "wall": wall_area,
                 "server": server_area, "page": page_area, "signals": signal_area}
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
