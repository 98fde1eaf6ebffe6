#!/usr/bin/python3
"""Another tool's Zarr store, as data is published: the 16-bit CT head at 4x a side (1024x1024x452,
948 MB; made once by scripts/resample_volume.py) written by zarr-python as Blosc-LZ4 (shuffle) in
chunks of 1x512x512, the way 2D viewers chunk it. With the default `isowall render` (1600x1200,
front view):

  - read whole from its folder, and over HTTP from a server on loopback (python's
    ThreadingHTTPServer in this process), both with --no-cache so every object is read: time to
    the first picture, --runs times each; the verdict: HTTP's median within 2x of the folder's;
  - over HTTP from a far server (each request answered --latency-ms late), one connection at a
    time against the default 8: time to the first picture;
  - paged under --memory-limit (default 256M) through its copy in a fresh cache folder (the first
    run writes the copy, the second finds it): the volume line, the store's reading line, the
    first picture, the peak resident memory, and whether the picture equals the one read whole.

Usage: /usr/bin/python3 scripts/bench_zarr.py [--build build] [--iso 600] [--limit 256M]
           [--runs 3] [--size 1600x1200] [--out out/bench-zarr] [--isowall BINARY]

Prints a markdown table and the verdicts, and writes them to OUT/zarr.md. Errors: one line naming
the program or the option, exit 1.
"""
import argparse
import functools
import http.server
import os
import re
import shutil
import statistics
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import bench_scaling as bs  # noqa: E402
from resample_volume import read_header  # noqa: E402

HEAD = os.path.join(ROOT, "..", "shared", "data", "cthead.nhdr")
SAME_PX = 1e-4  # the share of pixels that may differ between two pictures called the same


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--iso", type=float, default=600)
    p.add_argument("--limit", default="256M")
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--size", default="1600x1200")
    p.add_argument("--out", default=os.path.join(ROOT, "out", "bench-zarr"))
    p.add_argument("--isowall", help="the binary (default BUILD/bin/isowall)")
    p.add_argument("--latency-ms", type=float, default=20,
                   help="the far server's delay per request (default 20 ms)")
    a = p.parse_args(argv)
    if a.runs < 1:
        p.error("--runs: expected at least 1")
    a.isowall = a.isowall or os.path.join(a.build, "bin", "isowall")
    a.source = HEAD
    return a


def slices_store(a):
    """The head at 4x as a Zarr v2 array of Blosc-LZ4 chunks of 1x512x512 (made once)."""
    import numpy as np
    import zarr
    from numcodecs import Blosc
    nhdr, sizes = bs.scaled_volume(a, 4)
    path = os.path.join(a.build, "data", os.path.splitext(os.path.basename(nhdr))[0] + "_slices.zarr")
    if os.path.exists(os.path.join(path, ".zarray")):
        return path, nhdr
    sizes, dtype, _, _ = read_header(nhdr)
    raw = np.memmap(os.path.splitext(nhdr)[0] + ".raw", dtype=dtype, mode="r",
                    shape=(sizes[2], sizes[1], sizes[0]))
    print(f"making {path} once", flush=True)
    tmp = path + ".making"
    shutil.rmtree(tmp, ignore_errors=True)
    z = zarr.open_array(tmp, mode="w", shape=raw.shape, chunks=(1, 512, 512), dtype=raw.dtype,
                        compressor=Blosc(cname="lz4", clevel=5, shuffle=Blosc.SHUFFLE))
    for z0 in range(0, raw.shape[0], 32):
        z[z0:z0 + 32] = raw[z0:z0 + 32]
    os.rename(tmp, path)
    return path, nhdr


def serve(folder, latency_s=0.0):
    """A server of `folder` on loopback, answering each request `latency_s` late (a far server's
    round trip), keeping connections open (HTTP/1.1, TCP_NODELAY) as a web server or an object
    store does."""
    class Quiet(http.server.SimpleHTTPRequestHandler):
        protocol_version = "HTTP/1.1"
        # As web servers do on kept connections: without it the body waits for the client's
        # delayed ACK of the headers, 40 ms a request (Nagle's algorithm).
        disable_nagle_algorithm = True

        def do_GET(self):
            if latency_s:
                time.sleep(latency_s)
            super().do_GET()

        def log_message(self, *args):
            pass
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=folder))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def render(a, volume, png, *extra):
    out = bs.run([a.isowall, "render", "-v", volume, "--iso", f"{a.iso:g}", "--size", a.size, "-q",
                  "--out", png, *extra], f"isowall render {volume}")
    m = re.search(r"^first picture: ([\d.]+) s after the command began", out, re.M)
    rss = re.search(r"\| peak RSS ([\d.]+) MiB", out)
    if not m or not rss:
        raise bs.BenchError(f"isowall render {volume}: no first-picture or peak RSS line")
    line = lambda prefix: next((l for l in out.splitlines() if l.startswith(prefix)), "")  # noqa: E731
    return {"first_s": float(m.group(1)), "rss_mib": float(rss.group(1)),
            "volume": line("volume:"), "store": line("store:")}


def pixels_differing(a_png, b_png):
    import numpy as np
    from PIL import Image
    a, b = (np.asarray(Image.open(p).convert("RGB")).astype(int) for p in (a_png, b_png))
    return int((np.abs(a - b).max(axis=2) > 0).sum())


def main(argv):
    a = parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    store, nhdr = slices_store(a)
    gb = sum(os.path.getsize(os.path.join(store, f)) for f in os.listdir(store)) / 1e9
    sizes, dtype, _, _ = read_header(nhdr)
    voxels_gb = sizes[0] * sizes[1] * sizes[2] * dtype.itemsize / 1e9
    server = serve(os.path.dirname(store))
    url = f"http://127.0.0.1:{server.server_address[1]}/{os.path.basename(store)}"
    whole_png = os.path.join(a.out, "whole.png")
    rows, folder, over_http = [], [], []
    for i in range(a.runs):  # alternated, so drift falls on both alike
        folder.append(render(a, store, whole_png, "--no-cache"))
        over_http.append(render(a, url, os.path.join(a.out, "http.png"), "--no-cache"))
    server.shutdown()
    # A far server: every request answered --latency-ms late, one connection against the default.
    far = serve(os.path.dirname(store), a.latency_ms / 1000)
    far_url = f"http://127.0.0.1:{far.server_address[1]}/{os.path.basename(store)}"
    far_runs = {n: render(a, far_url, os.path.join(a.out, f"far{n}.png"), "--no-cache",
                          "--http-connections", str(n)) for n in (1, 8)}
    far.shutdown()
    cache = os.path.join(a.out, "cache")
    shutil.rmtree(cache, ignore_errors=True)
    paged_png = os.path.join(a.out, "paged.png")
    paged = [render(a, store, paged_png, "--cache-dir", cache, "--memory-limit", a.limit)
             for _ in range(2)]
    differ = pixels_differing(paged_png, whole_png)
    w, h = (int(n) for n in a.size.split("x"))
    pixels = w * h
    http_differ = pixels_differing(os.path.join(a.out, "http.png"), whole_png)

    f_med = statistics.median(r["first_s"] for r in folder)
    h_med = statistics.median(r["first_s"] for r in over_http)
    rows.append("| read | first picture (s) | peak RSS (MiB) |")
    rows.append("|---|---|---|")
    times = lambda runs: " / ".join(f"{r['first_s']:.2f}" for r in runs)  # noqa: E731
    rows.append(f"| folder, whole | {times(folder)} | {max(r['rss_mib'] for r in folder):.0f} |")
    rows.append(f"| HTTP, whole | {times(over_http)} | {max(r['rss_mib'] for r in over_http):.0f} |")
    for n, r in far_runs.items():
        rows.append(f"| HTTP, {a.latency_ms:g} ms a request, --http-connections {n}"
                    f"{' (default)' if n == 8 else ''} | {r['first_s']:.2f} | {r['rss_mib']:.0f} |")
    for name, r in zip(("paged, copy written", "paged, copy found"), paged):
        rows.append(f"| {name} (--memory-limit {a.limit}) | {r['first_s']:.2f} | {r['rss_mib']:.0f} |")
    lines = [f"store: {store}: {sizes[0]}x{sizes[1]}x{sizes[2]} {dtype}, {voxels_gb:.2f} GB of voxels "
             f"in {gb:.2f} GB of Blosc-LZ4 chunks of 1x512x512; iso {a.iso:g}, {a.size}", "", *rows, "",
             f"paged: {paged[0]['volume']}", f"paged: {paged[1]['volume']}", f"paged: {paged[1]['store']}",
             f"paged picture: {differ} px differ from the picture read whole; over HTTP: {http_differ} px",
             f"verdict: HTTP first picture {h_med / f_med:.2f}x the folder's (median of {a.runs}; "
             f"target at most 2x): {'holds' if h_med <= 2 * f_med else 'MISSED'}",
             f"far server: 8 connections {far_runs[1]['first_s'] / far_runs[8]['first_s']:.1f}x as fast "
             f"as 1 to the first picture",
             f"verdict: paged under {a.limit}, its picture the one read whole (at most {SAME_PX:g} of the "
             f"pixels differ: a progressive frame's last groups vary by a pixel or two between runs): "
             f"{'holds' if differ <= SAME_PX * pixels and 'paged, limit' in paged[0]['volume'] else 'MISSED'}"]
    text = "\n".join(lines)
    print(text)
    with open(os.path.join(a.out, "zarr.md"), "w") as f:
        f.write(text + "\n")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except bs.BenchError as e:
        print(f"bench_zarr: {e}", file=sys.stderr)
        sys.exit(1)
