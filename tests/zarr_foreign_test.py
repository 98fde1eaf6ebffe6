#!/usr/bin/python3
"""Zarr stores written by another tool (zarr-python 2.13 and numcodecs, python3-zarr) as
--volume: Blosc with lz4, zstd and zlib inside (shuffle, bit-shuffle and none), zstd, gzip, zlib,
lz4 and no compression; non-cubic chunks and one chunk for the whole volume; C and F order; a
big-endian dtype; "/" separators; chunks left out where they hold only the fill value; an
OME-Zarr 0.4 image of five axes (t, c, z, y, x) with a scale; a time point and a channel picked
by name (STORE:t=2,c=1) from chunks that hold several of each. Each renders the image the NRRD of
the same voxels renders, and `isowall info` states its size, type and spacing; one of them is
imported and the store renders the same image too. Bad stores (an unknown codec, chunks that do
not match the metadata, a dtype that is not a voxel type, a second time point not picked, a pick
out of range or of an axis that is not there) are one line
naming the file and the field, status 1, and no image.

Run: /usr/bin/python3 tests/zarr_foreign_test.py ISOWALL_BINARY SCRATCH_DIR   (CTest passes them)
"""
import json
import os
import shutil
import subprocess
import sys
import unittest

import numpy as np
import zarr
from numcodecs import GZip, LZ4, Zlib, Zstd, Blosc

ISOWALL = SCRATCH = None
SIZE = "96x72"


def blob(dtype=np.uint16):
    """A 30x26x21 (x, y, z) volume: two overlapping balls, values 0..1000, and an empty corner."""
    z, y, x = np.mgrid[0:21, 0:26, 0:30].astype(np.float32)
    a = 1000 * np.exp(-((x - 12) ** 2 + (y - 12) ** 2 + (z - 9) ** 2) / 40)
    b = 700 * np.exp(-((x - 20) ** 2 + (y - 15) ** 2 + (z - 12) ** 2) / 25)
    v = (a + b).astype(dtype)
    v[:, :, 24:] = 0  # whole chunks of zeros at x >= 24 for the small chunkings
    return v


def write_nrrd(path, v, spacing=(1, 1, 1)):
    kind = {np.dtype(np.uint16): "ushort", np.dtype(np.uint8): "uchar", np.dtype(np.float32): "float"}[v.dtype]
    with open(path + ".raw", "wb") as f:
        f.write(np.ascontiguousarray(v).astype(v.dtype.newbyteorder("<")).tobytes())
    with open(path, "w") as f:
        f.write(f"NRRD0004\ntype: {kind}\ndimension: 3\nsizes: {v.shape[2]} {v.shape[1]} {v.shape[0]}\n"
                f"spacings: {spacing[0]} {spacing[1]} {spacing[2]}\nendian: little\nencoding: raw\n"
                f"data file: {os.path.basename(path)}.raw\n\n")


def edit_zarray(store, **fields):
    with open(os.path.join(store, ".zarray")) as f:
        meta = json.load(f)
    meta.update(fields)
    with open(os.path.join(store, ".zarray"), "w") as f:
        json.dump(meta, f)


def run(*args):
    return subprocess.run([ISOWALL, *args, "--cache-dir", os.path.join(SCRATCH, "cache")],
                          capture_output=True, text=True, timeout=300)


def render(volume, out, iso=300):
    p = run("render", "-v", volume, "--iso", str(iso), "--size", SIZE, "-q", "--no-measure", "-o", out)
    return p


class ForeignZarr(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        shutil.rmtree(SCRATCH, ignore_errors=True)
        os.makedirs(SCRATCH)
        cls.v = blob()
        cls.nrrd = os.path.join(SCRATCH, "blob.nhdr")
        write_nrrd(cls.nrrd, cls.v)
        cls.reference = os.path.join(SCRATCH, "nrrd.png")
        p = render(cls.nrrd, cls.reference)
        assert p.returncode == 0, p.stderr

    def same_image(self, store, name):
        out = os.path.join(SCRATCH, name + ".png")
        p = render(store, out)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(out, "rb") as a, open(self.reference, "rb") as b:
            self.assertEqual(a.read(), b.read(), f"{name}: the image differs from the NRRD's")

    def write(self, name, data=None, **kw):
        path = os.path.join(SCRATCH, name + ".zarr")
        shutil.rmtree(path, ignore_errors=True)
        data = self.v if data is None else data
        a = zarr.open_array(path, mode="w", shape=data.shape, dtype=kw.pop("dtype", data.dtype),
                            chunks=kw.pop("chunks", (8, 8, 8)), **kw)
        a[...] = data
        return path

    def test_every_codec_renders_the_nrrds_image(self):
        codecs = {
            "blosc-lz4-shuffle": Blosc(cname="lz4", shuffle=Blosc.SHUFFLE),
            "blosc-zstd-bitshuffle": Blosc(cname="zstd", clevel=3, shuffle=Blosc.BITSHUFFLE),
            "blosc-zlib-noshuffle": Blosc(cname="zlib", shuffle=Blosc.NOSHUFFLE),
            "blosc-blosclz": Blosc(cname="blosclz"),
            "zstd": Zstd(level=1), "gzip": GZip(level=5), "zlib": Zlib(level=1), "lz4": LZ4(),
            "none": None,
        }
        for name, codec in codecs.items():
            with self.subTest(codec=name):
                self.same_image(self.write(name, compressor=codec), name)

    def test_chunk_shapes_orders_byte_orders_and_separators(self):
        cases = {
            "non-cubic": dict(chunks=(7, 16, 5)),
            "whole": dict(chunks=self.v.shape, compressor=Zstd(level=1)),
            "fortran": dict(chunks=(6, 9, 11), order="F"),
            "big-endian": dict(dtype=">u2", compressor=GZip()),
            "slashes": dict(dimension_separator="/"),
        }
        for name, kw in cases.items():
            with self.subTest(case=name):
                self.same_image(self.write(name, **kw), name)

    def test_left_out_chunks_are_the_fill_value(self):
        path = self.write("sparse", fill_value=0, write_empty_chunks=False)
        chunks = [f for f in os.listdir(path) if not f.startswith(".")]
        self.assertLess(len(chunks), 3 * 4 * 4)  # the empty corner's chunks were not written
        self.same_image(path, "sparse")
        # A fill value other than 0: a left-out chunk reads as it.
        path = self.write("filled", data=np.full(self.v.shape, 500, np.uint16), fill_value=500,
                          write_empty_chunks=False)
        self.assertEqual([f for f in os.listdir(path) if not f.startswith(".")], [])
        p = run("info", "-v", path)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("[500, 500]", p.stdout)

    def test_an_ome_zarr_image_of_five_axes_with_a_scale(self):
        path = os.path.join(SCRATCH, "ome.zarr")
        shutil.rmtree(path, ignore_errors=True)
        root = zarr.open_group(path, mode="w")
        root.create_dataset("0", data=self.v[np.newaxis, np.newaxis], chunks=(1, 1, 16, 16, 16),
                            compressor=Blosc(cname="lz4"))
        root.create_dataset("1", data=self.v[np.newaxis, np.newaxis, ::2, ::2, ::2], chunks=(1, 1, 16, 16, 16))
        axes = [{"name": "t", "type": "time"}, {"name": "c", "type": "channel"},
                {"name": "z", "type": "space", "unit": "millimeter"},
                {"name": "y", "type": "space", "unit": "millimeter"},
                {"name": "x", "type": "space", "unit": "millimeter"}]
        root.attrs["multiscales"] = [{"version": "0.4", "axes": axes, "datasets": [
            {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 2.0, 0.75, 0.5]}]},
            {"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 4.0, 1.5, 1.0]}]}]}]
        p = run("info", "-v", path)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("30x26x21 uint16", p.stdout)
        self.assertIn("spacing 0.5 0.75 2", p.stdout)
        nrrd = os.path.join(SCRATCH, "scaled.nhdr")
        write_nrrd(nrrd, self.v, (0.5, 0.75, 2.0))
        a, b = os.path.join(SCRATCH, "ome.png"), os.path.join(SCRATCH, "scaled.png")
        self.assertEqual(render(path, a).returncode, 0)
        self.assertEqual(render(nrrd, b).returncode, 0)
        with open(a, "rb") as fa, open(b, "rb") as fb:
            self.assertEqual(fa.read(), fb.read())
        # Imported, the store renders it too.
        store = os.path.join(SCRATCH, "imported.zarr")
        shutil.rmtree(store, ignore_errors=True)
        p = subprocess.run([ISOWALL, "import", path, "--out", store], capture_output=True, text=True, timeout=300)
        self.assertEqual(p.returncode, 0, p.stderr)
        c = os.path.join(SCRATCH, "imported.png")
        self.assertEqual(render(store, c).returncode, 0)
        with open(c, "rb") as fc, open(b, "rb") as fb:
            self.assertEqual(fc.read(), fb.read())

    def test_a_store_given_a_memory_limit_pages_through_its_copy(self):
        path = self.write("slices", chunks=(1, 26, 30), compressor=Blosc(cname="lz4"))
        out = os.path.join(SCRATCH, "paged.png")
        first = run("render", "-v", path, "--iso", "300", "--size", SIZE, "-q", "--no-measure",
                    "--memory-limit", "1M", "-o", out)
        self.assertEqual(first.returncode, 0, first.stderr)
        self.assertRegex(first.stdout, r"volume: .*slices.zarr .* in a store \(re-chunked into "
                                       r".*stores/[0-9a-f]{16}\.zarr in [0-9.]+ s; paged, limit 1 MiB\)")
        self.assertIn("re-chunk: [", first.stderr)  # the progress
        with open(out, "rb") as a, open(self.reference, "rb") as b:
            self.assertEqual(a.read(), b.read(), "the paged copy's image differs from the NRRD's")
        # Unchanged, the copy is found again; changed, the store gets a new copy.
        again = run("render", "-v", path, "--iso", "300", "--size", SIZE, "-q", "--no-measure",
                    "--memory-limit", "1M", "-o", out)
        self.assertIn("an earlier copy; paged", again.stdout)
        copies = os.listdir(os.path.join(SCRATCH, "cache", "stores"))
        a = zarr.open_array(path, mode="r+")
        a[10:12] = 0
        changed = run("render", "-v", path, "--iso", "300", "--size", SIZE, "-q", "--no-measure",
                      "--memory-limit", "1M", "-o", out)
        self.assertEqual(changed.returncode, 0, changed.stderr)
        self.assertNotIn("an earlier copy", changed.stdout)
        self.assertGreater(len(os.listdir(os.path.join(SCRATCH, "cache", "stores"))), len(copies))
        with open(out, "rb") as a, open(self.reference, "rb") as b:
            self.assertNotEqual(a.read(), b.read(), "the changed store drew the old copy")
        # Without a cache folder there is nowhere to copy it: one line.
        p = subprocess.run([ISOWALL, "render", "-v", path, "--memory-limit", "1M", "--no-cache",
                            "-o", os.path.join(SCRATCH, "nocache.png")],
                           capture_output=True, text=True, timeout=300)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertEqual(len(p.stderr.strip().splitlines()), 1, p.stderr)
        self.assertIn("--memory-limit", p.stderr)
        self.assertIn("--no-cache", p.stderr)
        self.assertFalse(os.path.exists(os.path.join(SCRATCH, "nocache.png")))

    def test_import_streams_a_store_a_slab_at_a_time(self):
        path = self.write("to-import", chunks=(4, 26, 30), compressor=Zstd(level=1))
        store = os.path.join(SCRATCH, "streamed.zarr")
        shutil.rmtree(store, ignore_errors=True)
        p = subprocess.run([ISOWALL, "import", path, "--out", store], capture_output=True,
                           text=True, timeout=300)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("source decoded a slab of planes at a time", p.stdout)
        out = os.path.join(SCRATCH, "streamed.png")
        self.assertEqual(render(store, out).returncode, 0)
        with open(out, "rb") as a, open(self.reference, "rb") as b:
            self.assertEqual(a.read(), b.read())

    def refused(self, path, *words):
        out = os.path.join(SCRATCH, "refused.png")
        if os.path.exists(out):
            os.remove(out)
        p = render(path, out)
        self.assertEqual(p.returncode, 1, p.stderr)
        lines = p.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, p.stderr)
        for w in words:
            self.assertIn(w, lines[0])
        self.assertFalse(os.path.exists(out))

    def test_bad_stores_are_one_line(self):
        path = self.write("unknown-codec", compressor=Zstd(level=1))
        edit_zarray(path, compressor={"id": "bz2", "level": 1})
        self.refused(path, ".zarray", "compressor", "bz2")
        # Metadata whose chunks are not the chunks written: the first chunk decodes to the wrong size.
        path = self.write("lying-chunks", compressor=GZip())
        edit_zarray(path, chunks=[8, 8, 4])
        self.refused(path, "0.0.0", "chunk", "expected 512")
        # A damaged chunk.
        path = self.write("damaged", compressor=Blosc(cname="lz4"))
        with open(os.path.join(path, "1.1.1"), "r+b") as f:
            f.truncate(20)
        self.refused(path, "1.1.1", "chunk")
        path = self.write("complex", data=self.v.astype(np.complex64))
        self.refused(path, "dtype", "<c8")
        path = self.write("two-times", data=np.stack([self.v, self.v]), chunks=(1, 8, 8, 8))
        self.refused(path, "axes", "axis 0 has 2 elements", path + ":0=0")
        self.refused(path + ":0=2", "axes", "0=2: axis 0 has 2 elements, expected an index from 0 to 1")
        self.refused(path + ":t=1", "axes", "expected AXIS=INDEX", "(0)", '"t=1"')

    def test_a_time_point_and_a_channel_picked_by_name(self):
        """Five axes of 3 time points and 2 channels, chunks holding 2 time points and both
        channels: each pick is the NRRD of its own voxels."""
        path = os.path.join(SCRATCH, "series.zarr")
        shutil.rmtree(path, ignore_errors=True)
        frames = np.stack([np.stack([self.v // (t + 1), self.v // 2 + 60 * t]) for t in range(3)])
        self.assertEqual(frames.shape[:2], (3, 2))
        root = zarr.open_group(path, mode="w")
        root.create_dataset("0", data=frames, chunks=(2, 2, 8, 16, 16), compressor=Zstd(level=1))
        axes = [{"name": n, "type": t} for n, t in
                (("t", "time"), ("c", "channel"), ("z", "space"), ("y", "space"), ("x", "space"))]
        root.attrs["multiscales"] = [{"version": "0.4", "axes": axes, "datasets": [
            {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1, 1, 1]}]}]}]
        for t, c in ((0, 0), (2, 1), (1, 1)):
            with self.subTest(t=t, c=c):
                nrrd = os.path.join(SCRATCH, f"frame{t}{c}.nhdr")
                write_nrrd(nrrd, frames[t, c])
                a, b = os.path.join(SCRATCH, f"pick{t}{c}.png"), os.path.join(SCRATCH, f"frame{t}{c}.png")
                pa = render(f"{path}:t={t},c={c}", a, iso=200)
                self.assertEqual(pa.returncode, 0, pa.stderr)
                self.assertEqual(render(nrrd, b, iso=200).returncode, 0)
                with open(a, "rb") as fa, open(b, "rb") as fb:
                    self.assertEqual(fa.read(), fb.read())
        self.refused(path + ":c=1", "axes", "axis t has 3 elements", path + ":t=0")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit("usage: zarr_foreign_test.py ISOWALL_BINARY SCRATCH_DIR")
    ISOWALL, SCRATCH = sys.argv[1], sys.argv[2]
    del sys.argv[1:3]
    unittest.main()
