#!/usr/bin/python3
"""VTK reference for the benchmarks: vtkFlyingEdges3D on a volume, then VTK's first rendered frame
of the front full view at the given size. Needs Debian's python3-vtk9 and an X display (run it
under `xvfb-run -a`). Prints "key value" lines: fe_s, first_frame_s, total_s, triangles.

Usage: xvfb-run -a /usr/bin/python3 scripts/vtk_reference.py RAW DIMS_X DIMS_Y DIMS_Z TYPE
       SX SY SZ ISO WIDTHxHEIGHT [--threads N]
(RAW is headerless voxel data, x fastest, little endian; bench scripts write it.)
"""
import argparse
import math
import time

import numpy
import vtk
from vtk.util import numpy_support

NUMPY_TYPES = {"uint8": "u1", "int8": "i1", "uint16": "<u2", "int16": "<i2", "uint32": "<u4",
               "int32": "<i4", "float32": "<f4", "float64": "<f8"}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("raw")
    ap.add_argument("dims", nargs=3, type=int)
    ap.add_argument("type", choices=sorted(NUMPY_TYPES))
    ap.add_argument("spacing", nargs=3, type=float)
    ap.add_argument("iso", type=float)
    ap.add_argument("size")
    ap.add_argument("--threads", type=int, default=0, help="SMP threads for flying edges (0: VTK's default)")
    a = ap.parse_args()
    if a.threads:
        vtk.vtkSMPTools.Initialize(a.threads)
    w, h = (int(x) for x in a.size.split("x"))

    voxels = numpy.fromfile(a.raw, dtype=NUMPY_TYPES[a.type])
    image = vtk.vtkImageData()
    image.SetDimensions(*a.dims)
    image.SetSpacing(*a.spacing)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(voxels, deep=False))

    window = vtk.vtkRenderWindow()
    window.SetSize(w, h)
    window.SetOffScreenRendering(1)
    renderer = vtk.vtkRenderer()
    renderer.SetBackground(0, 0, 0)
    window.AddRenderer(renderer)
    # Create the GL context and compile the surface shaders before timing, as isowall does: an
    # interactive viewer pays both once at start-up.
    warm = vtk.vtkSphereSource()
    warm_mapper = vtk.vtkPolyDataMapper()
    warm_mapper.SetInputConnection(warm.GetOutputPort())
    warm_actor = vtk.vtkActor()
    warm_actor.SetMapper(warm_mapper)
    renderer.AddActor(warm_actor)
    window.Render()
    renderer.RemoveActor(warm_actor)

    t0 = time.perf_counter()
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, a.iso)
    fe.ComputeNormalsOn()
    fe.ComputeScalarsOff()
    fe.Update()
    t1 = time.perf_counter()
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(fe.GetOutput())
    mapper.ScalarVisibilityOff()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    renderer.AddActor(actor)
    # The front full view: along +y, +z up, fit to the volume.
    cam = renderer.GetActiveCamera()
    bounds = [0, (a.dims[0] - 1) * a.spacing[0], 0, (a.dims[1] - 1) * a.spacing[1], 0,
              (a.dims[2] - 1) * a.spacing[2]]
    centre = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2]
    cam.SetFocalPoint(*centre)
    cam.SetPosition(centre[0], centre[1] - 3 * max(bounds), centre[2])
    cam.SetViewUp(0, 0, 1)
    cam.SetViewAngle(30)
    renderer.ResetCamera(bounds)
    renderer.ResetCameraClippingRange()
    window.Render()
    t2 = time.perf_counter()
    print(f"fe_s {t1 - t0:.4f}")
    print(f"first_frame_s {t2 - t1:.4f}")
    print(f"total_s {t2 - t0:.4f}")
    print(f"triangles {fe.GetOutput().GetNumberOfPolys()}")
    print(f"threads {vtk.vtkSMPTools.GetEstimatedNumberOfThreads()}")


if __name__ == "__main__":
    main()
