#!/usr/bin/python3
"""A store that `isowall import` writes opens in zarr-python (Debian's python3-zarr, with its
numcodecs) voxel for voxel, every level of its multiscale pyramid too: the point of writing Zarr is that users' other tools read it. Three
volumes: float32 and int16 noise of sides that are not multiples of a brick (the padded edge
bricks must crop away), and the shared tooth (uint16) when ../shared/data is there. The
OME-Zarr attributes carry the axes and the spacing as a scale.

Run: /usr/bin/python3 tests/store_zarr_test.py BUILD_DIR   (CTest passes the path)
"""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import zarr

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.environ.get("ISOWALL_SHARED_DATA", os.path.join(os.path.dirname(ROOT), "shared", "data"))
BUILD = None


def isowall(*args):
    r = subprocess.run([os.path.join(BUILD, "bin", "isowall"), *args], capture_output=True,
                       text=True, timeout=300)
    if r.returncode != 0:
        raise AssertionError(f"isowall {' '.join(args)}: exit {r.returncode}: {r.stderr}")
    return r


class StoreInZarr(unittest.TestCase):
    def check(self, out, raw, dims, type_name, spacing=None):
        store = os.path.join(out, os.path.basename(raw) + ".zarr")
        args = ["import", raw, "--dims", *map(str, dims), "--type", type_name, "--out", store,
                "-q", "--no-cache"]
        if spacing:
            args += ["--spacing", *map(str, spacing)]
        isowall(*args)
        g = zarr.open_group(store, mode="r")
        a = g["0"]
        self.assertEqual(a.shape, tuple(reversed(dims)))
        want = np.fromfile(raw, dtype=a.dtype).reshape(a.shape)
        self.assertTrue(np.array_equal(a[:], want))
        ms = g.attrs["multiscales"][0]
        self.assertEqual([x["name"] for x in ms["axes"]], ["z", "y", "x"])
        base = list(reversed(spacing)) if spacing else [1.0, 1.0, 1.0]
        # Every level of the pyramid, as OME-Zarr lists it: every 2^k-th voxel, its scale 2^k
        # times level 0's, down to a level that fits one chunk a side.
        self.assertGreater(len(ms["datasets"]), 1)
        for k, d in enumerate(ms["datasets"]):
            step = 2 ** k
            self.assertEqual(d["path"], str(k))
            self.assertEqual(d["coordinateTransformations"][0]["scale"],
                             [x * step for x in base])
            self.assertTrue(np.array_equal(g[d["path"]][:], want[::step, ::step, ::step]),
                            f"level {k}")
        self.assertLessEqual(max(g[str(len(ms["datasets"]) - 1)].shape), 32)

    def test_noise_with_padded_edges(self):
        rng = np.random.default_rng(7)
        with tempfile.TemporaryDirectory() as out:
            for dtype, name in ((np.float32, "float32"), (np.int16, "int16")):
                with self.subTest(dtype=name):
                    dims = (45, 70, 33)  # x y z, none a multiple of 32
                    v = (rng.standard_normal(dims[::-1]) * 1000).astype(dtype)
                    raw = os.path.join(out, name + ".raw")
                    v.tofile(raw)
                    self.check(out, raw, dims, name, spacing=(0.5, 0.75, 2.0))

    def test_shared_tooth(self):
        tooth = os.path.join(DATA, "tooth.raw")
        if not os.path.exists(tooth):
            self.skipTest(f"no shared data at {DATA}")
        with tempfile.TemporaryDirectory() as out:
            self.check(out, tooth, (103, 94, 161), "uint16")


if __name__ == "__main__":
    BUILD = os.path.abspath(sys.argv.pop(1)) if len(sys.argv) > 1 else os.path.join(ROOT, "build")
    unittest.main()
