#!/usr/bin/python3
"""Trilinear resampling of a raw NRRD volume (detached header), for studies at other sizes.

    scripts/resample_volume.py IN.nhdr --scale 0.5 [--out-dir build/data] [--name NAME]
    scripts/resample_volume.py IN.nhdr --sizes 256 256 117

Writes NAME.raw and NAME.nhdr (same voxel type, little-endian, raw) into --out-dir, one output
slice at a time, so a 4x copy of the 512-wide head (3.9 GB) needs a few hundred MB of memory.
Sample i of an axis with n_in inputs and n_out outputs sits at i * (n_in - 1) / (n_out - 1) in
the input (corners aligned), so the volume keeps its extent and its isosurfaces keep their shape.
Integer types are rounded to the nearest value. An output whose header already names the same
input and sizes is kept (printed as such), so the script can run once per machine.
Errors print one line naming the file and field, and exit 1 with no output file left behind.
"""
import argparse
import os
import sys
import time

import numpy as np

TYPES = {
    "uint8": np.uint8, "uchar": np.uint8, "unsigned char": np.uint8,
    "uint16": np.uint16, "ushort": np.uint16, "unsigned short": np.uint16,
    "int16": np.int16, "short": np.int16,
    "float": np.float32,
}


class InputError(Exception):
    pass


def read_header(path):
    """Fields of a detached NRRD header we can read: sizes, type, endian, data file."""
    try:
        with open(path, "r", encoding="latin-1") as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise InputError(f"{path}: cannot read: {e.strerror}")
    if not lines or not lines[0].startswith("NRRD"):
        raise InputError(f"{path}: magic: not a NRRD header")
    fields = {}
    for line in lines[1:]:
        if not line or line.startswith("#") or ":" not in line:
            continue
        key, value = line.split(":", 1)
        fields[key.strip()] = value.strip()
    for key in ("type", "sizes", "data file", "encoding"):
        if key not in fields:
            raise InputError(f"{path}: {key}: missing")
    if fields["encoding"] != "raw":
        raise InputError(f"{path}: encoding: only raw is read, got {fields['encoding']}")
    if fields["type"] not in TYPES:
        raise InputError(f"{path}: type: {fields['type']} is not one of {sorted(TYPES)}")
    try:
        sizes = [int(v) for v in fields["sizes"].split()]
    except ValueError:
        raise InputError(f"{path}: sizes: expected three integers, got {fields['sizes']}")
    if len(sizes) != 3 or min(sizes) < 2:
        raise InputError(f"{path}: sizes: expected three integers >= 2, got {fields['sizes']}")
    dtype = np.dtype(TYPES[fields["type"]])
    if fields.get("endian", "little") == "big":
        dtype = dtype.newbyteorder(">")
    raw = os.path.join(os.path.dirname(path), fields["data file"])
    expected = sizes[0] * sizes[1] * sizes[2] * dtype.itemsize
    try:
        actual = os.path.getsize(raw)
    except OSError as e:
        raise InputError(f"{raw}: data file: cannot read: {e.strerror}")
    if actual < expected:
        raise InputError(f"{raw}: data file: {actual} bytes, the header's sizes need {expected}")
    return sizes, dtype, raw, fields["type"]


def read_spacings(path):
    """The header's `spacings` (three numbers), or None when it has none."""
    with open(path, "r", encoding="latin-1") as f:
        for line in f.read().splitlines()[1:]:
            if line.startswith("spacings:"):
                try:
                    values = [float(v) for v in line.split(":", 1)[1].split()]
                except ValueError:
                    raise InputError(f"{path}: spacings: expected three numbers, got {line}")
                if len(values) != 3 or not all(v > 0 and v == v and v != float("inf") for v in values):
                    raise InputError(f"{path}: spacings: expected three positive numbers, got {line}")
                return values
    return None


def axis_weights(n_in, n_out):
    """For each output sample: the two input indices around it and the second one's weight."""
    pos = np.arange(n_out, dtype=np.float64) * ((n_in - 1) / (n_out - 1))
    lo = np.minimum(np.floor(pos).astype(np.int64), n_in - 2)
    return lo, lo + 1, (pos - lo).astype(np.float32)


def resample(src, sizes_out, write_slice, progress):
    """Separable trilinear: z between two input slices, then y rows, then x columns."""
    nz_in = src.shape[0]
    z0, z1, wz = axis_weights(nz_in, sizes_out[2])
    y0, y1, wy = axis_weights(src.shape[1], sizes_out[1])
    x0, x1, wx = axis_weights(src.shape[2], sizes_out[0])
    wy, wx = wy[:, None], wx[None, :]
    for k in range(sizes_out[2]):
        a = src[z0[k]].astype(np.float32)
        plane = a + (src[z1[k]].astype(np.float32) - a) * wz[k]
        rows = plane[y0] + (plane[y1] - plane[y0]) * wy
        write_slice(rows[:, x0] + (rows[:, x1] - rows[:, x0]) * wx)
        progress(k + 1, sizes_out[2])


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("input", help="detached NRRD header (.nhdr) of a raw volume")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--scale", type=float, help="factor per axis (0.5 = half as many a side)")
    g.add_argument("--sizes", type=int, nargs=3, metavar=("X", "Y", "Z"), help="output sizes")
    p.add_argument("--out-dir", default="build/data", help="folder for the copy (default %(default)s)")
    p.add_argument("--name", help="output name (default: input name + sizes)")
    a = p.parse_args(argv)

    sizes, dtype, raw, type_name = read_header(a.input)
    if a.scale is not None:
        if not (0 < a.scale <= 16):
            raise InputError(f"--scale: expected a factor in (0, 16], got {a.scale}")
        out_sizes = [max(2, int(round(s * a.scale))) for s in sizes]
    else:
        if min(a.sizes) < 2 or max(a.sizes) > 16384:
            raise InputError(f"--sizes: each must be in [2, 16384], got {a.sizes}")
        out_sizes = list(a.sizes)
    base = os.path.splitext(os.path.basename(a.input))[0]
    name = a.name or f"{base}_{out_sizes[0]}x{out_sizes[1]}x{out_sizes[2]}"
    os.makedirs(a.out_dir, exist_ok=True)
    nhdr = os.path.join(a.out_dir, name + ".nhdr")
    out_raw = os.path.join(a.out_dir, name + ".raw")
    source_line = f"# resampled trilinearly from {os.path.abspath(a.input)} {sizes}"
    # The copy spans the same object box: sample i sits at i * (n_in - 1) / (n_out - 1).
    spacings = read_spacings(a.input)
    spacing_line = [] if spacings is None else ["spacings: " + " ".join(
        f"{sp * (n_in - 1) / (n_out - 1):.9g}" for sp, n_in, n_out in zip(spacings, sizes, out_sizes))]
    header = "\n".join([
        "NRRD0004", source_line, f"type: {type_name}", "dimension: 3",
        "sizes: {} {} {}".format(*out_sizes), "endian: little", "encoding: raw"] + spacing_line + [
        f"data file: {name}.raw", ""])
    out_dtype = dtype.newbyteorder("<")
    expected = out_sizes[0] * out_sizes[1] * out_sizes[2] * out_dtype.itemsize
    if (os.path.exists(nhdr) and open(nhdr, encoding="latin-1").read() == header
            and os.path.exists(out_raw) and os.path.getsize(out_raw) == expected):
        print(f"resample: {nhdr} is already there ({out_sizes}), kept")
        return 0

    src = np.memmap(raw, dtype=dtype, mode="r", shape=(sizes[2], sizes[1], sizes[0]))
    info = np.iinfo(out_dtype) if out_dtype.kind in "iu" else None
    tmp = out_raw + ".part"
    t0 = time.monotonic()
    last = [t0]

    def progress(done, total):
        now = time.monotonic()
        if now - last[0] >= 5 or done == total:
            last[0] = now
            print(f"resample: {done}/{total} slices, {now - t0:.1f} s", flush=True)

    try:
        with open(tmp, "wb") as f:
            def write_slice(s):
                if info is not None:
                    s = np.clip(np.rint(s), info.min, info.max)
                f.write(s.astype(out_dtype).tobytes())
            print(f"resample: {a.input} {sizes} -> {out_raw} {out_sizes}", flush=True)
            resample(src, out_sizes, write_slice, progress)
        os.replace(tmp, out_raw)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    with open(nhdr + ".part", "w", encoding="latin-1") as f:
        f.write(header)
    os.replace(nhdr + ".part", nhdr)
    print(f"resample: wrote {nhdr}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        print(f"resample: {e}", file=sys.stderr)
        sys.exit(1)
