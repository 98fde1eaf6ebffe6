#!/usr/bin/python3
"""Zarr stores written by another tool (zarr-python 2.13 and numcodecs, python3-zarr) as
--volume: Blosc with lz4, zstd and zlib inside (shuffle, bit-shuffle and none), zstd, gzip, zlib,
lz4 and no compression; non-cubic chunks and one chunk for the whole volume; C and F order; a
big-endian dtype; "/" separators; chunks left out where they hold only the fill value; an
OME-Zarr 0.4 image of five axes (t, c, z, y, x) with a scale; a time point and a channel picked
by name (STORE:t=2,c=1) from chunks that hold several of each. Each renders the image the NRRD of
the same voxels renders, and `isowall info` states its size, type and spacing; one of them is
imported and the store renders the same image too. Zarr v3 arrays written by hand to its
specification (zarr-python 2.13 writes only v2): Blosc, gzip with crc32c, zstd, transposed and
big-endian chunks, both key encodings, and sharding_indexed with inner chunks and whole shards left
out; an OME-Zarr 0.5 image of two levels, the second picked with STORE:level=1 and drawn at its
own scale. A store given --memory-limit pages through its copy in the cache folder. Bad stores (an unknown codec, chunks that do
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


def crc32c(data):
    table = crc32c.table
    if table is None:
        table = crc32c.table = []
        for i in range(256):
            c = i
            for _ in range(8):
                c = (c >> 1) ^ (0x82F63B78 if c & 1 else 0)
            table.append(c)
    c = 0xFFFFFFFF
    for b in data:
        c = table[(c ^ b) & 0xFF] ^ (c >> 8)
    return (c ^ 0xFFFFFFFF).to_bytes(4, "little")


crc32c.table = None


def v3_encode(block, order=None, endian="little", compressor=None, crc=False):
    """One v3 chunk's bytes: transpose, bytes, a compressor, crc32c (each where given)."""
    if order is not None:
        block = np.transpose(block, order)
    data = np.ascontiguousarray(block).astype(block.dtype.newbyteorder("<" if endian == "little" else ">")).tobytes()
    if compressor is not None:
        data = bytes(compressor.encode(data))
    return data + crc32c(data) if crc else data


def v3_codecs(order=None, endian="little", compressor=None, crc=False):
    names = {Blosc: "blosc", GZip: "gzip", Zstd: "zstd"}
    out = [{"name": "transpose", "configuration": {"order": list(order)}}] if order is not None else []
    out.append({"name": "bytes", "configuration": {"endian": endian}})
    if compressor is not None:
        out.append({"name": names[type(compressor)], "configuration": {}})
    if crc:
        out.append({"name": "crc32c"})
    return out


def write_v3(path, v, chunks, shard=None, encoding="default", sep="/", names=("z", "y", "x"), **codec):
    """A Zarr v3 array of `v` (zarr-python 2.13 writes only v2): chunks padded to their shape at
    the edges; with `shard` (an inner chunk shape) each chunk is a shard of inner chunks under an
    index with a CRC-32C at its end, an inner chunk of only zeros left out."""
    shutil.rmtree(path, ignore_errors=True)
    os.makedirs(path)
    meta = {"zarr_format": 3, "node_type": "array", "shape": list(v.shape), "data_type": str(v.dtype),
            "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": list(chunks)}},
            "chunk_key_encoding": {"name": encoding, "configuration": {"separator": sep}},
            "fill_value": 0, "dimension_names": list(names)}
    if shard:
        meta["codecs"] = [{"name": "sharding_indexed", "configuration": {
            "chunk_shape": list(shard), "codecs": v3_codecs(**codec),
            "index_codecs": [{"name": "bytes", "configuration": {"endian": "little"}}, {"name": "crc32c"}],
            "index_location": "end"}}]
    else:
        meta["codecs"] = v3_codecs(**codec)
    with open(os.path.join(path, "zarr.json"), "w") as f:
        json.dump(meta, f)
    grid = [-(-n // c) for n, c in zip(v.shape, chunks)]
    for idx in np.ndindex(*grid):
        block = np.zeros(chunks, v.dtype)
        part = v[tuple(slice(i * c, (i + 1) * c) for i, c in zip(idx, chunks))]
        block[tuple(slice(0, n) for n in part.shape)] = part
        if shard:
            body, index = b"", b""
            inner_grid = [c // s for c, s in zip(chunks, shard)]
            for j in np.ndindex(*inner_grid):
                inner = block[tuple(slice(i * s, (i + 1) * s) for i, s in zip(j, shard))]
                if not inner.any():
                    index += b"\xff" * 16
                    continue
                data = v3_encode(inner, **codec)
                index += len(body).to_bytes(8, "little") + len(data).to_bytes(8, "little")
                body += data
            data = body + index + crc32c(index)
        else:
            data = v3_encode(block, **codec)
        key = ("c" + sep if encoding == "default" else "") + sep.join(str(i) for i in idx)
        os.makedirs(os.path.dirname(os.path.join(path, key)), exist_ok=True)
        with open(os.path.join(path, key), "wb") as f:
            f.write(data)
    return path


class ZarrV3(unittest.TestCase):
    """Zarr v3 arrays and OME-Zarr 0.5 images, written by hand to the v3 specification."""

    @classmethod
    def setUpClass(cls):
        cls.v = blob()
        cls.nrrd = os.path.join(SCRATCH, "v3-blob.nhdr")
        write_nrrd(cls.nrrd, cls.v)
        cls.reference = os.path.join(SCRATCH, "v3-nrrd.png")
        assert render(cls.nrrd, cls.reference).returncode == 0

    def same_image(self, path, reference=None):
        out = path + ".png"
        p = render(path, out)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(out, "rb") as a, open(reference or self.reference, "rb") as b:
            self.assertEqual(a.read(), b.read(), f"{path}: the image differs from the NRRD's")

    def test_arrays_of_each_codec_chain_render_the_nrrds_image(self):
        cases = {
            "v3-blosc": dict(chunks=(8, 8, 8), compressor=Blosc(cname="lz4", shuffle=Blosc.SHUFFLE)),
            "v3-gzip-crc-transposed-big": dict(chunks=(5, 26, 7), order=(2, 1, 0), endian="big",
                                               compressor=GZip(), crc=True, encoding="v2", sep="."),
            "v3-zstd-permuted": dict(chunks=(21, 13, 16), order=(1, 2, 0), compressor=Zstd(level=1)),
            "v3-sharded": dict(chunks=(16, 16, 16), shard=(8, 8, 8), compressor=Zstd(level=1), crc=True),
            "v3-sharded-raw-F": dict(chunks=(8, 16, 32), shard=(4, 8, 8), order=(2, 1, 0)),
        }
        for name, kw in cases.items():
            with self.subTest(name):
                path = write_v3(os.path.join(SCRATCH, name + ".zarr"), self.v, **kw)
                self.same_image(path)
        # A shard left out entirely, and inner chunks left out, read as the fill value.
        sharded = os.path.join(SCRATCH, "v3-sharded.zarr")
        def index_has_a_gap(file):
            with open(file, "rb") as f:
                index = f.read()[-4 - 16 * 8:-4]
            return b"\xff" * 16 in [index[i:i + 16] for i in range(0, len(index), 16)]
        self.assertTrue(any(index_has_a_gap(os.path.join(r, f))
                            for r, _, fs in os.walk(os.path.join(sharded, "c")) for f in fs))
        p = run("info", "-v", sharded)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("Zarr v3 array", p.stdout)
        self.assertIn("16x16x16 shards of 8x8x8", p.stdout)

    def test_an_ome_zarr_05_image_and_its_levels(self):
        group = os.path.join(SCRATCH, "ome05.zarr")
        shutil.rmtree(group, ignore_errors=True)
        os.makedirs(group)
        write_v3(os.path.join(group, "0"), self.v, (8, 8, 8), compressor=Blosc(cname="zstd"))
        half = np.ascontiguousarray(self.v[::2, ::2, ::2])
        write_v3(os.path.join(group, "1"), half, (8, 8, 8), compressor=GZip())
        axes = [{"name": n, "type": "space"} for n in ("z", "y", "x")]
        datasets = [{"path": str(i), "coordinateTransformations": [{"type": "scale", "scale": [s] * 3}]}
                    for i, s in ((0, 1), (1, 2))]
        with open(os.path.join(group, "zarr.json"), "w") as f:
            json.dump({"zarr_format": 3, "node_type": "group", "attributes": {"ome": {
                "version": "0.5", "multiscales": [{"axes": axes, "datasets": datasets}]}}}, f)
        self.same_image(group)
        p = run("info", "-v", group + ":level=1")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("15x13x11 uint16", p.stdout)
        self.assertIn("spacing 2 2 2", p.stdout)
        self.assertIn("level 1 of 2", p.stdout)
        nrrd = os.path.join(SCRATCH, "half.nhdr")
        write_nrrd(nrrd, half, spacing=(2, 2, 2))
        reference = os.path.join(SCRATCH, "half.png")
        self.assertEqual(render(nrrd, reference).returncode, 0)
        self.same_image(group + ":level=1", reference)
        ForeignZarr.refused(self, group + ":level=2", "level=2: the image has 2 levels")

    def test_bad_v3_stores_are_one_line(self):
        path = write_v3(os.path.join(SCRATCH, "v3-bz2.zarr"), self.v, (8, 8, 8), compressor=Zstd(level=1))
        with open(os.path.join(path, "zarr.json")) as f:
            meta = json.load(f)
        meta["codecs"][1]["name"] = "bz2"
        with open(os.path.join(path, "zarr.json"), "w") as f:
            json.dump(meta, f)
        ForeignZarr.refused(self, path, "zarr.json", "codecs[1]", "bz2")
        path = write_v3(os.path.join(SCRATCH, "v3-crc.zarr"), self.v, (8, 8, 8), compressor=GZip(), crc=True)
        with open(os.path.join(path, "c", "1", "1", "1"), "r+b") as f:
            data = bytearray(f.read())
            data[len(data) // 2] ^= 0xFF
            f.seek(0)
            f.write(data)
        ForeignZarr.refused(self, path, "c/1/1/1", "chunk")
        path = write_v3(os.path.join(SCRATCH, "v3-level.zarr"), self.v, (8, 8, 8))
        ForeignZarr.refused(self, path + ":level=1", "level=1", "a plain array has one level")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit("usage: zarr_foreign_test.py ISOWALL_BINARY SCRATCH_DIR")
    ISOWALL, SCRATCH = sys.argv[1], sys.argv[2]
    del sys.argv[1:3]
    unittest.main()
