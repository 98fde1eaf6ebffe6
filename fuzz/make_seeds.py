#!/usr/bin/env python3
"""Writes the seed corpora of the text harnesses (fuzz/corpus/{nrrd,metaimage,wall,script}); the wire
seeds come from the fuzz_wire_seeds program (fuzz/wire_seeds.cpp). Run from anywhere; the files
it writes are committed. NRRD seeds are tiny volumes of each encoding Teem reads, attached and
detached (after a line "@data.raw" comes data.raw, see fuzz/fuzz_nrrd.cpp)."""
import bz2
import gzip
import struct
import zlib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / "fuzz" / "corpus"
MARK = b"\n@data.raw\n"


def header(type_, sizes, encoding, extra=()):
    lines = ["NRRD0004", f"type: {type_}", "dimension: 3", f"sizes: {sizes}",
             f"encoding: {encoding}", *extra]
    return ("\n".join(lines) + "\n\n").encode()


def nrrd_seeds():
    u8 = bytes(range(8))
    f32 = struct.pack("<8f", *[0.5 * i for i in range(8)])
    i16be = struct.pack(">12h", *range(-6, 6))
    yield "raw-u8", header("uint8", "2 2 2", "raw", ["spacings: 1 1 2"]) + u8
    yield "raw-f32", header("float", "2 2 2", "raw", ["endian: little"]) + f32
    yield "raw-i16-big", header("short", "3 2 2", "raw", ["endian: big"]) + i16be
    yield "raw-space-dirs", header("uchar", "2 2 2", "raw", [
        "space: right-anterior-superior", "space directions: (0.5,0,0) (0,0.5,0) (0,0,2)",
        "space origin: (0,0,0)"]) + u8
    yield "gzip-u8", header("uint8", "2 2 2", "gzip") + gzip.compress(u8)
    yield "gzip-f32", header("float", "2 2 2", "gz", ["endian: little"]) + gzip.compress(f32)
    yield "bzip2-u8", header("uchar", "2 2 2", "bzip2") + bz2.compress(u8)
    yield "hex-u8", header("uint8", "2 2 2", "hex") + u8.hex().encode() + b"\n"
    yield "ascii-u8", header("uint8", "2 2 2", "ascii") + b"0 1 2 3 4 5 6 7\n"
    yield "ascii-f32", header("float", "2 2 2", "text") + b"0 .5 1 1.5\n2 2.5 3 3.5\n"
    yield "detached-raw", header("uint8", "2 2 2", "raw", ["data file: data.raw"]) + MARK + u8
    yield "detached-byteskip", header("uint8", "2 2 2", "raw", [
        "data file: data.raw", "byte skip: 4"]) + MARK + b"head" + u8
    yield "detached-byteskip-end", header("uint8", "2 2 2", "raw", [
        "data file: data.raw", "byte skip: -1"]) + MARK + b"junk" + u8
    yield "detached-lineskip", header("uint8", "2 2 2", "raw", [
        "data file: data.raw", "line skip: 1"]) + MARK + b"a line\n" + u8
    yield "detached-gzip", header("uint8", "2 2 2", "gzip", [
        "data file: data.raw"]) + MARK + gzip.compress(u8)
    yield "two-d", ("NRRD0004\ntype: uint8\ndimension: 2\nsizes: 2 2\nencoding: raw\n\n"
                    ).encode() + u8[:4]
    yield "header-only-v1", b"NRRD0001\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n" \
        b"encoding: raw\n\n" + u8


def mha(type_, data_file, extra=()):
    lines = ["ObjectType = Image", "NDims = 3", "BinaryData = True", "DimSize = 2 2 2",
             *extra, f"ElementType = {type_}", f"ElementDataFile = {data_file}"]
    return ("\n".join(lines) + "\n").encode()


def metaimage_seeds():
    """MetaImage headers (fuzz/fuzz_metaimage.cpp): LOCAL ones with their data after the header,
    detached ones with data.raw after a line "@data.raw"."""
    u8 = bytes(range(8))
    i16be = struct.pack(">8h", *range(-4, 4))
    f32 = struct.pack("<8f", *[0.5 * i for i in range(8)])
    yield "local-u8", mha("MET_UCHAR", "LOCAL", ["ElementSpacing = 1 1 2"]) + u8
    yield "local-i16-msb", mha("MET_SHORT", "LOCAL", [
        "BinaryDataByteOrderMSB = True", "ElementByteOrderMSB = True"]) + i16be
    yield "local-zlib-f32", mha("MET_FLOAT", "LOCAL", [
        "CompressedData = True", f"CompressedDataSize = {len(zlib.compress(f32))}"]) + \
        zlib.compress(f32)
    yield "local-oriented", mha("MET_UCHAR", "LOCAL", [
        "TransformMatrix = 0 1 0 -1 0 0 0 0 1", "Offset = -10 20 5.5",
        "AnatomicalOrientation = RAI", "ElementSize = 0.5 0.5 1"]) + u8
    yield "detached-raw", mha("MET_UCHAR", "data.raw") + MARK + u8
    yield "detached-headersize-end", mha("MET_UCHAR", "data.raw", ["HeaderSize = -1"]) + \
        MARK + b"junk" + u8
    yield "detached-headersize", mha("MET_UCHAR", "data.raw", ["HeaderSize = 4"]) + \
        MARK + b"junk" + u8


def write(folder, name, data):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_bytes(data)


def main():
    for name, data in nrrd_seeds():
        write(CORPUS / "nrrd", name, data)
    for name, data in metaimage_seeds():
        write(CORPUS / "metaimage", name, data)
    for toml in sorted((ROOT / "walls").glob("*.toml")):
        write(CORPUS / "wall", toml.name, toml.read_bytes())
    scripts = {
        "demo": "orbit 30 -10\nlook-at 0 -500 100  255 255 117   # from the front\nzoom 1.5\n"
                "iso 105\nwait rays 10000\nwait time 0.5\nwait done\nsnapshot bone\nquit\n",
        "run": "wait rays 200\norbit 60 -20\niso 160\nwait done\nsnapshot last\nquit\n",
        "pan": "pan 0.25 -0.5\r\nzoom 0.8\r\n\n# comment only\n\t\n",
        "bad-command": "orbit 30 0\nfly away\nwait done\n",
        "bad-number": "orbit 1 nan\n",
        "console-line": "snapshot typed",
    }
    for name, text in scripts.items():
        write(CORPUS / "script", name, text.encode())


if __name__ == "__main__":
    main()
