#!/usr/bin/python3
"""Foundation benchmark: octree build, full extraction and render on the default volume and the
shared CT heads, with VTK's vtkFlyingEdges3D (one thread) on the same volume and isovalue in the
same run when Debian's python3-vtk9 is installed.

Usage: scripts/bench_foundation.py [--build build] [--repeats 3] [--data ../shared/data]
Targets (printed as PASS/FAIL lines): our extraction no slower than flying edges on one core;
octree overhead <= 1/8 of the volume bytes.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run_ours(bench, volume, iso, repeats, save=None):
    cmd = [bench, volume, str(iso), str(repeats), "osmesa"] + ([save] if save else [])
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    figures = {}
    for line in out.splitlines():
        key, _, value = line.partition(" ")
        figures[key] = value
    return figures


NUMPY_TYPES = {"uint8": "u1", "int8": "i1", "uint16": "<u2", "int16": "<i2", "uint32": "<u4",
               "int32": "<i4", "float32": "<f4", "float64": "<f8"}


def run_vtk(raw_path, ours, iso, repeats):
    try:
        import numpy
        import vtk
        from vtk.util import numpy_support
    except ImportError:
        return None
    vtk.vtkSMPTools.Initialize(1)  # one core, like our serial extraction
    dims = [int(x) for x in ours["dims"].split()]
    spacing = [float(x) for x in ours["spacing"].split()]
    voxels = numpy.fromfile(raw_path, dtype=NUMPY_TYPES[ours["type"]])
    image = vtk.vtkImageData()
    image.SetDimensions(*dims)
    image.SetSpacing(*spacing)
    array = numpy_support.numpy_to_vtk(voxels, deep=False)
    image.GetPointData().SetScalars(array)
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, iso)
    fe.ComputeNormalsOn()  # we compute gradient normals too
    fe.ComputeScalarsOff()
    times = []
    for _ in range(repeats):
        fe.Modified()
        t0 = time.perf_counter()
        fe.Update()
        times.append(time.perf_counter() - t0)
    return {"extract_s": min(times),
            "triangles": fe.GetOutput().GetNumberOfPolys()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"))
    args = ap.parse_args()
    bench = os.path.join(args.build, "tests", "isowall_bench_foundation")
    if not os.path.exists(bench):
        sys.exit(f"bench_foundation: {bench} not found; build first (bash scripts/setup.sh)")

    tmp = tempfile.mkdtemp(prefix="isowall-bench-")
    cases = [("phantom", "phantom", 50), ("phantom", "phantom", 160)]
    for name, iso in [("vhp_ct_head", 40), ("vhp_ct_head", 105), ("cthead", 600), ("cthead", 1650)]:
        path = os.path.join(args.data, name + ".nhdr")
        if os.path.exists(path):
            cases.append((name, path, iso))
        else:
            print(f"note: {path} absent, skipped")

    header = (f"{'volume':<12} {'iso':>5} {'octree s':>9} {'Mvox/s':>7} {'overhead':>8} "
              f"{'extract s':>9} {'triangles':>9} {'render s':>8} | {'FE 1-core s':>11} {'FE tris':>9} {'FE/ours':>7}")
    print(header)
    print("-" * len(header))
    failures = 0
    raw = os.path.join(tmp, "volume.raw")
    for name, volume, iso in cases:
        ours = run_ours(bench, volume, iso, args.repeats, raw)
        fe = run_vtk(raw, ours, iso, args.repeats)
        ext = float(ours["extract_s"])
        overhead = float(ours["octree_overhead"])
        row = (f"{name:<12} {iso:>5} {float(ours['octree_build_s']):>9.3f} "
               f"{float(ours['octree_voxels_per_s']) / 1e6:>7.0f} {overhead:>8.2%} {ext:>9.3f} "
               f"{int(ours['triangles']):>9} {float(ours['render_s']):>8.3f} | ")
        if fe:
            ratio = fe["extract_s"] / ext
            row += f"{fe['extract_s']:>11.3f} {fe['triangles']:>9} {ratio:>7.2f}"
            if ratio < 1.0:
                failures += 1
        else:
            row += f"{'(no python3-vtk9)':>29}"
        if overhead > 1 / 8:
            failures += 1
        print(row)
    os.remove(raw)
    os.rmdir(tmp)
    print()
    print("targets: extraction no slower than flying edges on one core (FE/ours >= 1); "
          "octree overhead <= 12.5% of the volume bytes")
    print("result:", "PASS" if failures == 0 else f"FAIL ({failures} misses)")
    return 0 if failures == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
