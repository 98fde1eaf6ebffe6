#!/usr/bin/python3
"""The flying-edges side of the FE + Embree peer: VTK's vtkFlyingEdges3D over a whole
volume on N threads (vtkSMPTools), timed alone, then the mesh written for bench/peer's
isowall-peer (the file layout is in bench/peer/peer_mesh.h). Needs Debian's python3-vtk9.

Usage: /usr/bin/python3 scripts/fe_mesh.py VOLUME.nhdr ISO OUT.mesh [--threads 2] [--repeat 1]

VOLUME is a detached NRRD header of raw little- or big-endian data (as scripts/resample_volume.py
reads them; `spacings:` is honoured, 1 1 1 without it), placed as isowall places it: voxel
(i, j, k) at (i, j, k) * spacing. The voxels are read into memory before the clock starts, as
isowall loads a volume before it extracts. With --repeat N the filter runs N times in the
process and fe_s is the last run's (fe_first_s the first's): the steady state `isowall render
--warm-up` measures. Prints "key value" lines: fe_s, fe_first_s, triangles, vertices,
threads. Errors: one line naming the file or option, exit 1.
"""
import argparse
import os
import struct
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from resample_volume import InputError, read_header  # noqa: E402

MAGIC = b"ISOWMESH"
VERSION = 1


def read_spacing(path):
    with open(path, "r", encoding="latin-1") as f:
        for line in f:
            if line.startswith("spacings:"):
                try:
                    values = [float(v) for v in line.split(":", 1)[1].split()]
                except ValueError:
                    values = []
                if len(values) != 3 or min(values) <= 0:
                    raise InputError(f"{path}: spacings: expected three positive numbers, got {line.strip()}")
                return values
            if line.startswith("space directions:"):
                raise InputError(f"{path}: space directions: not read here; give spacings instead")
    return [1.0, 1.0, 1.0]


def write_mesh(path, bounds_max, points, triangles):
    with open(path, "wb") as f:
        f.write(MAGIC + struct.pack("<II", VERSION, 0))
        f.write(struct.pack("<6f", 0.0, 0.0, 0.0, *bounds_max))
        f.write(struct.pack("<QQ", len(points), len(triangles)))
        f.write(np.ascontiguousarray(points, dtype="<f4").tobytes())
        f.write(np.ascontiguousarray(triangles, dtype="<u4").tobytes())


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0], epilog=__doc__.split("\n", 2)[2],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("volume", help="detached NRRD header (.nhdr) of raw data")
    ap.add_argument("iso", type=float, help="isovalue")
    ap.add_argument("out", help="mesh file to write (for isowall-peer)")
    ap.add_argument("--threads", type=int, default=2, help="vtkSMPTools threads (default %(default)s)")
    ap.add_argument("--repeat", type=int, default=1, help="runs of the filter; the last is timed (default %(default)s)")
    a = ap.parse_args(argv)
    if not 1 <= a.repeat <= 20:
        raise InputError(f"--repeat: expected an integer in [1, 20], got {a.repeat}")
    if a.threads < 1:
        raise InputError(f"--threads: expected a positive integer, got {a.threads}")
    sizes, dtype, raw, _ = read_header(a.volume)
    spacing = read_spacing(a.volume)
    try:
        import vtk
        from vtk.util import numpy_support
    except ImportError:
        raise InputError("vtk: python3-vtk9 is not installed (apt-get install python3-vtk9)")
    vtk.vtkSMPTools.Initialize(a.threads)

    count = sizes[0] * sizes[1] * sizes[2]
    voxels = np.fromfile(raw, dtype=dtype, count=count).astype(dtype.newbyteorder("="), copy=False)
    image = vtk.vtkImageData()
    image.SetDimensions(*sizes)
    image.SetSpacing(*spacing)
    image.SetOrigin(0, 0, 0)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(voxels, deep=False))

    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, a.iso)
    fe.ComputeNormalsOn()  # as isowall's full extraction, which gives every vertex a normal
    fe.ComputeGradientsOff()
    fe.ComputeScalarsOff()
    times = []
    for _ in range(a.repeat):
        fe.Modified()  # else VTK keeps the last output and Update does nothing
        t0 = time.perf_counter()
        fe.Update()
        times.append(time.perf_counter() - t0)

    out = fe.GetOutput()
    n_points = out.GetNumberOfPoints()
    points = numpy_support.vtk_to_numpy(out.GetPoints().GetData()) if n_points else np.zeros((0, 3))
    polys = out.GetPolys()
    connectivity = numpy_support.vtk_to_numpy(polys.GetConnectivityArray()) if out.GetNumberOfPolys() else np.zeros(0)
    triangles = connectivity.reshape(-1, 3)
    bounds_max = [(n - 1) * s for n, s in zip(sizes, spacing)]
    write_mesh(a.out, bounds_max, points.reshape(-1, 3), triangles)
    print(f"fe_s {times[-1]:.4f}")
    print(f"fe_first_s {times[0]:.4f}")
    print(f"triangles {len(triangles)}")
    print(f"vertices {n_points}")
    print(f"threads {vtk.vtkSMPTools.GetEstimatedNumberOfThreads()}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except (InputError, OSError) as e:
        print(f"fe_mesh: {e}", file=sys.stderr)
        sys.exit(1)
