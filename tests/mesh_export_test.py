#!/usr/bin/python3
"""`isowall extract` to every mesh format, each file opened by its reference reader: VTK's PLY,
STL, OBJ and XML PolyData readers (python3-vtk9) and the Khronos glTF validator (npm's
gltf-validator, web/tools/validate_glb.mjs); a .glb compressed with meshopt is decoded by
meshoptimizer's own decoder (web/tools/decode_meshopt_glb.mjs) and validated again. Every file
has the PLY's triangles and bounds; the
volumes are the built-in phantom and a small sphere with anisotropic spacing (bounds in object
units). An unknown extension is one line, status 1, and no file.

Run: /usr/bin/python3 tests/mesh_export_test.py ISOWALL_BINARY SCRATCH_DIR   (CTest passes them)
"""
import json
import os
import shutil
import subprocess
import sys
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VALIDATE = os.path.join(ROOT, "web", "tools", "validate_glb.mjs")
DECODE = os.path.join(ROOT, "web", "tools", "decode_meshopt_glb.mjs")
ISOWALL = SCRATCH = None
FORMATS = ("ply", "stl", "obj", "vtp", "glb")


def extract(out, *volume):
    return subprocess.run([ISOWALL, "extract", "-o", out, *volume], capture_output=True, text=True,
                          timeout=300)


def vtk_read(path):
    """(triangles, bounds) as VTK reads the file."""
    import vtk
    ext = os.path.splitext(path)[1]
    reader = {".ply": vtk.vtkPLYReader, ".stl": vtk.vtkSTLReader, ".obj": vtk.vtkOBJReader,
              ".vtp": vtk.vtkXMLPolyDataReader}[ext]()
    if ext == ".stl":
        reader.MergingOff()  # merging would drop the triangles whose corners coincide
    reader.SetFileName(path)
    reader.Update()
    poly = reader.GetOutput()
    cells = poly.GetPolys()
    sizes = {cells.GetCellSize(i) for i in range(min(cells.GetNumberOfCells(), 1000))}
    return poly.GetNumberOfPolys(), poly.GetBounds(), sizes, poly


def glb_report(path):
    p = subprocess.run(["node", VALIDATE, path], capture_output=True, text=True, timeout=120)
    if p.returncode == 2 or not p.stdout.strip():
        raise AssertionError(f"validate_glb: {p.stderr}")
    return json.loads(p.stdout.splitlines()[0])


def glb_bounds(path):
    """The POSITION accessor's min and max, from the JSON chunk."""
    with open(path, "rb") as f:
        data = f.read()
    n = int.from_bytes(data[12:16], "little")
    doc = json.loads(data[20:20 + n])
    pos = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    return pos["min"], pos["max"]


def sphere_volume(path):
    """A 24x20x16 uint8 ball, raw: brighter towards the centre."""
    dims = (24, 20, 16)
    with open(path, "wb") as f:
        for z in range(dims[2]):
            for y in range(dims[1]):
                f.write(bytes(max(0, 200 - int(100 * ((x - 11.5) ** 2 / 36 + (y - 9.5) ** 2 / 25 +
                                                     (z - 7.5) ** 2 / 16))) for x in range(dims[0])))
    return ["-v", path, "--dims", "24", "20", "16", "--type", "uint8", "--spacing", "0.5", "1", "2",
            "--iso", "100"]


class MeshExport(unittest.TestCase):
    def check_all_formats(self, name, volume):
        out = os.path.join(SCRATCH, name)
        os.makedirs(out, exist_ok=True)
        for ext in FORMATS:
            p = extract(os.path.join(out, f"s.{ext}"), *volume)
            self.assertEqual(p.returncode, 0, p.stderr)
        tris, bounds, sizes, ply = vtk_read(os.path.join(out, "s.ply"))
        self.assertGreater(tris, 500)
        self.assertEqual(sizes, {3})
        self.assertIsNotNone(ply.GetPointData().GetNormals())
        for ext in ("stl", "obj", "vtp"):
            t, b, s, poly = vtk_read(os.path.join(out, f"s.{ext}"))
            self.assertEqual(t, tris, ext)
            self.assertEqual(s, {3}, ext)
            for got, want in zip(b, bounds):
                self.assertAlmostEqual(got, want, places=4, msg=ext)
            if ext != "stl":  # STL has facet normals only
                self.assertIsNotNone(poly.GetPointData().GetNormals(), ext)
                self.assertEqual(poly.GetNumberOfPoints(), ply.GetNumberOfPoints(), ext)
        r = glb_report(os.path.join(out, "s.glb"))
        self.assertEqual((r["errors"], r["warnings"]), (0, 0), r["messages"])
        self.assertEqual(r["triangles"], tris)
        self.assertEqual(r["vertices"], ply.GetNumberOfPoints())
        lo, hi = glb_bounds(os.path.join(out, "s.glb"))
        for a in range(3):
            self.assertAlmostEqual(lo[a], bounds[2 * a], places=4)
            self.assertAlmostEqual(hi[a], bounds[2 * a + 1], places=4)
        self.check_meshopt(out, volume, tris, bounds, ply.GetNumberOfPoints())
        return bounds

    def check_meshopt(self, out, volume, tris, bounds, points):
        """The meshopt-compressed .glb: smaller, valid, and decoded by meshoptimizer's own decoder
        into the plain file's mesh (the validator cannot decode the extension itself)."""
        packed, decoded = os.path.join(out, "s-meshopt.glb"), os.path.join(out, "s-decoded.glb")
        p = extract(packed, *volume, "--compress", "meshopt")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertLess(os.path.getsize(packed), 0.7 * os.path.getsize(os.path.join(out, "s.glb")))
        r = glb_report(packed)
        self.assertEqual((r["errors"], r["warnings"]), (0, 0), r["messages"])
        self.assertTrue(any("EXT_meshopt_compression" in m for m in r["messages"]), r["messages"])
        d = subprocess.run(["node", DECODE, packed, decoded], capture_output=True, text=True, timeout=120)
        self.assertEqual(d.returncode, 0, d.stderr)
        self.assertEqual(json.loads(d.stdout)["views"], 3)
        r = glb_report(decoded)
        self.assertEqual((r["errors"], r["warnings"], r["infos"]), (0, 0, 0), r["messages"])
        self.assertEqual(r["triangles"], tris)
        self.assertLessEqual(r["vertices"], points)  # a vertex no triangle uses is left out
        self.assertGreater(r["vertices"], points // 2)
        lo, hi = glb_bounds(decoded)
        for a in range(3):
            self.assertAlmostEqual(lo[a], bounds[2 * a], places=4)
            self.assertAlmostEqual(hi[a], bounds[2 * a + 1], places=4)

    def test_the_phantom_in_every_format(self):
        self.check_all_formats("phantom", [])

    def test_anisotropic_spacing_in_object_units(self):
        os.makedirs(SCRATCH, exist_ok=True)
        bounds = self.check_all_formats("sphere", sphere_volume(os.path.join(SCRATCH, "ball.raw")))
        # The ball spans about x 5.5..17.5 voxels (x0.5), y 4.5..14.5 (x1), z 3.5..11.5 (x2).
        self.assertLess(bounds[1] - bounds[0], 7)
        self.assertGreater(bounds[5] - bounds[4], 14)

    def test_an_unknown_extension_is_one_line_and_no_file(self):
        out = os.path.join(SCRATCH, "bad")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        p = extract(os.path.join(out, "s.gltf"))
        self.assertEqual(p.returncode, 1)
        lines = p.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, p.stderr)
        self.assertIn("--out: unknown mesh format \".gltf\"", lines[0])
        self.assertEqual(os.listdir(out), [])
        p = extract(os.path.join(out, "s.ply"), "--compress", "meshopt")
        self.assertEqual(p.returncode, 1)
        self.assertEqual(len(p.stderr.strip().splitlines()), 1, p.stderr)
        self.assertIn("--compress", p.stderr)
        self.assertEqual(os.listdir(out), [])


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit("usage: mesh_export_test.py ISOWALL_BINARY SCRATCH_DIR")
    ISOWALL, SCRATCH = sys.argv[1], sys.argv[2]
    del sys.argv[1:3]
    unittest.main()
