#!/usr/bin/python3
"""Zarr stores over HTTP (`--volume http://...`, readers/http_fetch.h) against a server in this
process on loopback: a store written by zarr-python renders the image its folder renders, a
time point picked by URL too; a chunk answered 503 twice is fetched on the third try; the fetched
objects are kept, so a second render needs no server; and each way a server fails ends in one
line naming the URL and the object, status 1 and no image: a chunk answered 500 every time, a
server that stops sending (--http-timeout 1), a body cut short of its Content-Length, a chunk
that is cut short but says so in its Content-Length (the decoder refuses it: never a wrong
image), a 403 on the metadata, and no server at all.

Run: /usr/bin/python3 tests/zarr_http_test.py ISOWALL_BINARY SCRATCH_DIR   (CTest passes them)
"""
import http.server
import os
import shutil
import subprocess
import sys
import threading
import unittest

import numpy as np
import zarr
from numcodecs import Blosc

ISOWALL = SCRATCH = None
SIZE = "96x72"


class Faults:
    """What the server does per path: a list of actions taken one per request (the last one
    repeats): "ok", "503", "500", "403", "stall", "cut" (a Content-Length the body does not
    reach), "short" (half the body, with a Content-Length that says so), "hold" (answered only
    once another request has come in: a client that fetches one object at a time never gets
    it, and the test's end lets it go). `most_at_once` counts the requests in flight together;
    `connections` the client's connections (a kept one serves several requests)."""

    def __init__(self):
        self.lock = threading.Lock()
        self.plan = {}
        self.requests = []
        self.stop = threading.Event()
        self.arrived = threading.Condition(self.lock)
        self.in_flight = self.most_at_once = 0
        self.peers = set()

    def begin(self, peer):
        with self.lock:
            self.in_flight += 1
            self.most_at_once = max(self.most_at_once, self.in_flight)
            self.peers.add(peer)
            self.arrived.notify_all()

    def end(self):
        with self.lock:
            self.in_flight -= 1

    def hold(self, seen):
        """Until a request after the `seen`-th has come in (or the test ends)."""
        with self.lock:
            self.arrived.wait_for(lambda: len(self.requests) > seen or self.stop.is_set())

    def next(self, path):
        with self.lock:
            self.requests.append(path)
            steps = self.plan.get(path)
            if not steps:
                return "ok"
            return steps.pop(0) if len(steps) > 1 else steps[0]


def make_handler(root, faults):
    class Handler(http.server.BaseHTTPRequestHandler):
        protocol_version = "HTTP/1.1"
        disable_nagle_algorithm = True  # as web servers do on kept connections

        def log_message(self, *args):
            pass

        def do_GET(self):
            faults.begin(self.client_address)
            try:
                self.answer()
            finally:
                faults.end()

        def answer(self):
            action = faults.next(self.path)
            if action == "hold":
                faults.hold(len(faults.requests))
            file = os.path.join(root, self.path.lstrip("/"))
            if action in ("503", "500", "403"):
                self.send_response(int(action))
                self.send_header("Content-Length", "0")
                self.end_headers()
                return
            if not os.path.isfile(file):
                self.send_response(404)
                self.send_header("Content-Length", "0")
                self.end_headers()
                return
            with open(file, "rb") as f:
                body = f.read()
            if action == "short":
                body = body[: len(body) // 2]
            self.send_response(200)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            if action == "stall":
                faults.stop.wait(60)  # the client gives up first, or the test ends
                return
            if action == "cut":
                self.wfile.write(body[: len(body) // 2])
                self.wfile.flush()
                self.close_connection = True
                return
            self.wfile.write(body)

    return Handler


def run(*args):
    return subprocess.run([ISOWALL, *args], capture_output=True, text=True, timeout=300)


def render(volume, out, *extra):
    return run("render", "-v", volume, "--iso", "300", "--size", SIZE, "-q", "--no-measure", "-o", out,
               *extra)


class ZarrOverHttp(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        shutil.rmtree(SCRATCH, ignore_errors=True)
        os.makedirs(SCRATCH)
        z, y, x = np.mgrid[0:21, 0:26, 0:30].astype(np.float32)
        v = (1000 * np.exp(-((x - 12) ** 2 + (y - 12) ** 2 + (z - 9) ** 2) / 40)).astype(np.uint16)
        cls.store = os.path.join(SCRATCH, "blob.zarr")
        a = zarr.open_array(cls.store, mode="w", shape=v.shape, chunks=(8, 8, 8), dtype=v.dtype,
                            compressor=Blosc(cname="zstd"))
        a[...] = v
        series = os.path.join(SCRATCH, "series.zarr")
        s = zarr.open_array(series, mode="w", shape=(2,) + v.shape, chunks=(1, 8, 8, 8), dtype=v.dtype)
        s[0] = v // 3
        s[1] = v
        cls.faults = Faults()
        cls.server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), make_handler(SCRATCH, cls.faults))
        cls.thread = threading.Thread(target=cls.server.serve_forever, daemon=True)
        cls.thread.start()
        cls.url = f"http://127.0.0.1:{cls.server.server_address[1]}"
        cls.reference = os.path.join(SCRATCH, "folder.png")
        p = render(cls.store, cls.reference, "--no-cache")
        assert p.returncode == 0, p.stderr

    @classmethod
    def tearDownClass(cls):
        cls.faults.stop.set()
        cls.server.shutdown()
        cls.server.server_close()

    def setUp(self):
        self.faults.plan.clear()
        self.faults.requests.clear()

    def same_as_folder(self, out):
        with open(out, "rb") as a, open(self.reference, "rb") as b:
            self.assertEqual(a.read(), b.read())

    def refused(self, volume, *words, extra=()):
        out = os.path.join(SCRATCH, "refused.png")
        if os.path.exists(out):
            os.remove(out)
        p = render(volume, out, "--no-cache", *extra)
        self.assertEqual(p.returncode, 1, p.stderr)
        lines = p.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, p.stderr)
        for w in words:
            self.assertIn(w, lines[0])
        self.assertFalse(os.path.exists(out))

    def test_a_store_over_http_renders_its_folders_image(self):
        out = os.path.join(SCRATCH, "http.png")
        p = render(self.url + "/blob.zarr", out, "--no-cache")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.same_as_folder(out)
        self.assertIn("/blob.zarr/0.0.0", self.faults.requests)
        # A time point picked in the URL.
        a, b = os.path.join(SCRATCH, "t1.png"), os.path.join(SCRATCH, "t1-folder.png")
        self.assertEqual(render(self.url + "/series.zarr:0=1", a, "--no-cache").returncode, 0)
        self.assertEqual(render(os.path.join(SCRATCH, "series.zarr") + ":0=1", b, "--no-cache").returncode, 0)
        with open(a, "rb") as fa, open(b, "rb") as fb:
            self.assertEqual(fa.read(), fb.read())
        # Imported from its URL, the store renders the folder's image too.
        imported = os.path.join(SCRATCH, "imported.zarr")
        shutil.rmtree(imported, ignore_errors=True)
        p = run("import", self.url + "/blob.zarr", "--out", imported, "--no-cache")
        self.assertEqual(p.returncode, 0, p.stderr)
        c = os.path.join(SCRATCH, "imported.png")
        self.assertEqual(render(imported, c, "--no-cache").returncode, 0)
        self.same_as_folder(c)

    def test_a_chunk_refused_twice_comes_on_the_third_try(self):
        self.faults.plan["/blob.zarr/1.1.1"] = ["503", "503", "ok"]
        out = os.path.join(SCRATCH, "retried.png")
        p = render(self.url + "/blob.zarr", out, "--no-cache")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(self.faults.requests.count("/blob.zarr/1.1.1"), 3)
        self.same_as_folder(out)

    def test_fetched_objects_are_kept_and_read_again_without_the_server(self):
        cache = os.path.join(SCRATCH, "cache")
        shutil.rmtree(cache, ignore_errors=True)
        out = os.path.join(SCRATCH, "cached.png")
        self.assertEqual(render(self.url + "/blob.zarr", out, "--cache-dir", cache).returncode, 0)
        self.assertTrue(os.listdir(os.path.join(cache, "http")))
        asked = len(self.faults.requests)
        for path in list(set(self.faults.requests)):
            self.faults.plan[path] = ["500"]  # the server is broken now
        os.remove(out)
        p = render(self.url + "/blob.zarr", out, "--cache-dir", cache)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.same_as_folder(out)
        # The octree cache keys on the objects' copies, so the octree is found, not built.
        self.assertIn("octree: mapped", p.stdout)
        # Only what was absent (a 404, which is not kept) was asked again.
        self.assertTrue(all(r.endswith((".zarray", ".zattrs", ".zgroup")) or r not in
                            self.faults.requests[:asked] for r in self.faults.requests[asked:]))

    def test_a_store_over_http_pages_through_its_copy(self):
        cache = os.path.join(SCRATCH, "paged-cache")
        shutil.rmtree(cache, ignore_errors=True)
        out = os.path.join(SCRATCH, "paged.png")
        # A chunk cut short while it is copied: one line, no image, and no copy left to reuse.
        self.faults.plan["/blob.zarr/1.1.1"] = ["cut"] * 4
        p = render(self.url + "/blob.zarr", out, "--cache-dir", cache, "--memory-limit", "1M")
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn(self.url + "/blob.zarr/1.1.1", p.stderr.strip().splitlines()[-1])
        self.assertFalse(os.path.exists(out))
        self.assertEqual([f for f in os.listdir(os.path.join(cache, "stores")) if f.endswith(".zarr")], [])
        self.faults.plan.clear()
        p = render(self.url + "/blob.zarr", out, "--cache-dir", cache, "--memory-limit", "1M")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertRegex(p.stdout, r"volume: http://.*/blob.zarr .*\(re-chunked into .*; paged, limit 1 MiB\)")
        self.same_as_folder(out)

    def test_a_rows_chunks_come_over_kept_connections_several_at_once(self):
        self.faults.peers.clear()
        self.faults.most_at_once = 0
        self.faults.plan["/blob.zarr/0.0.0"] = ["hold"]  # waits for a second request
        out = os.path.join(SCRATCH, "parallel.png")
        p = render(self.url + "/blob.zarr", out, "--no-cache", "--http-connections", "4")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.same_as_folder(out)
        self.assertGreaterEqual(self.faults.most_at_once, 2)
        # 3x4x4 chunks and the metadata over at most 4 connections per process (the child that
        # learns the size, then the one that reads), each kept for the next object.
        self.assertLessEqual(len(self.faults.peers), 2 * 4 + 2)
        self.assertGreater(len(self.faults.requests), 3 * 4 * 4)

    def test_a_wall_reads_a_url_and_a_picked_folder_on_every_rank(self):
        """Each rank fetches the URL (or reads the folder of STORE:0=1) itself; before, a rank
        that found no such file asked the master for a store's bricks and the job ended. The
        mosaic is the single render's within the wall tests' thresholds."""
        from PIL import Image
        wall = os.path.join(SCRATCH, "2x2.toml")
        with open(wall, "w") as f:
            f.write("tiles = [2, 2]\ntile_size_px = [48, 36]\n")
        env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        for name, volume, folder in (
                ("url", self.url + "/series.zarr:0=1", os.path.join(SCRATCH, "series.zarr") + ":0=1"),
                ("picked", os.path.join(SCRATCH, "series.zarr") + ":0=1", None)):
            with self.subTest(name):
                mosaic, single = (os.path.join(SCRATCH, f"wall-{name}-{k}.png") for k in ("mosaic", "single"))
                p = subprocess.run(["mpirun", "--oversubscribe", "-np", "5", ISOWALL, "wall", "--wall", wall,
                                    "-v", volume, "--iso", "300", "--no-cache", "--out", mosaic],
                                   capture_output=True, text=True, timeout=300, env=env)
                self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
                self.assertEqual(render(folder or volume, single, "--no-cache").returncode, 0)
                a, b = (np.asarray(Image.open(f).convert("RGB")).astype(int) for f in (mosaic, single))
                self.assertEqual(a.shape, b.shape)
                covered_a, covered_b = a.any(axis=2), b.any(axis=2)
                iou = (covered_a & covered_b).sum() / max(1, (covered_a | covered_b).sum())
                self.assertGreaterEqual(iou, 0.999)
                self.assertGreaterEqual((np.abs(a - b).max(axis=2) == 0).mean(), 0.999)
                self.assertGreater(covered_a.mean(), 0.02)  # a surface was drawn

    def test_every_failure_of_the_server_is_one_line(self):
        store = self.url + "/blob.zarr"
        self.faults.plan["/blob.zarr/0.1.0"] = ["500"]
        self.refused(store, store + "/0.1.0", "chunk", "HTTP 500", "after 4 tries")
        self.faults.plan.clear()
        self.faults.plan["/blob.zarr/0.1.1"] = ["stall"]
        self.refused(store, store + "/0.1.1", "sent nothing for 1 s", extra=("--http-timeout", "1"))
        self.faults.plan.clear()
        self.faults.plan["/blob.zarr/1.0.1"] = ["cut"]
        self.refused(store, store + "/1.0.1", "cut short")
        self.faults.plan.clear()
        self.faults.plan["/blob.zarr/1.1.0"] = ["short"]
        self.refused(store, store + "/1.1.0", "chunk")
        self.faults.plan.clear()
        self.faults.requests.clear()
        self.faults.plan["/blob.zarr/.zarray"] = ["403"]
        self.refused(store, store + "/.zarray", "HTTP 403")
        self.assertEqual(self.faults.requests.count("/blob.zarr/.zarray"), 1)  # not tried again
        self.faults.plan.clear()
        self.refused("http://127.0.0.1:9/blob.zarr", "127.0.0.1:9/blob.zarr/.zarray", "after 4 tries")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit("usage: zarr_http_test.py ISOWALL_BINARY SCRATCH_DIR")
    ISOWALL, SCRATCH = sys.argv[1], sys.argv[2]
    del sys.argv[1:3]
    unittest.main()
