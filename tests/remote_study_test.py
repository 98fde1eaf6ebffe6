#!/usr/bin/python3
"""Tests of scripts/remote_study.py: a small study on the phantom over one paced link, as a user
would run it, and its errors.

Run: /usr/bin/python3 tests/remote_study_test.py PATH/TO/isowall   (CTest passes the path)
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "remote_study.py")
ISOWALL = None
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def study(*args):
    return subprocess.run([sys.executable, SCRIPT, "--isowall", ISOWALL, *args],
                          capture_output=True, text=True, timeout=600)


class RemoteStudy(unittest.TestCase):
    def test_small_study_writes_tables_plots_and_every_point(self):
        with tempfile.TemporaryDirectory() as out:
            p = study("--volume", "phantom", "--rates", "50", "--cases", "2,4,5",
                      "--size", "160x120", "--out", out)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(os.path.join(out, "study.json")) as f:
                study_json = json.load(f)
            res = study_json["results"]["50"]
            self.assertEqual(sorted(res), ["2", "4", "5", "5new"])
            for case, r in res.items():
                # Every frame reaches C = 100%, with points in time and bytes order.
                points = r["points"]
                self.assertTrue(all(pt is not None for pt in points), case)
                times = [pt["time_s"] for pt in points]
                self.assertEqual(times, sorted(times), case)
                self.assertGreater(r["total_bytes"], 0, case)
            # The cache (case 4, the turned view) needs far fewer bytes than a new isovalue.
            self.assertLess(res["4"]["total_bytes"], res["2"]["total_bytes"] / 2)
            self.assertLess(res["5"]["total_bytes"], res["4"]["total_bytes"])
            with open(os.path.join(out, "study.md")) as f:
                md = f.read()
            self.assertIn("Bytes to reach C", md)
            self.assertIn("Seconds to reach C at 50 Mbit/s", md)
            self.assertIn("bytes, case 4, C = 90%", md)
            self.assert_targets(md, study_json)
            for png in ("c_vs_time.png", "c_vs_bytes.png", "50mbps_case4.png"):
                with open(os.path.join(out, png), "rb") as f:
                    self.assertEqual(f.read(8), PNG_MAGIC, png)

    def assert_targets(self, md, study_json):
        # The text's bytes are scaled by our voxels over its 256x256x209, and the factor printed.
        dims = study_json["dims"]
        scale = dims[0] * dims[1] * dims[2] / (256 * 256 * 209)
        self.assertAlmostEqual(study_json["scale"], scale)
        self.assertRegex(md, rf"- scale factor for the volume's size: {scale:.3f} = "
                             rf"{dims[0]}x{dims[1]}x{dims[2]} / 256x256x209 voxels")
        self.assertIn("1 run each", md)
        # Every case in the tables gets a verdict at every C: 5 against the text's case 4, and
        # a new isovalue in our encoding against the text's best (case 3 at 90%).
        for case in ("2", "4", "5new", "5"):
            for c in ("90", "99", "99.9", "100"):
                self.assertRegex(md, rf"- bytes, case {case}, C = {c}%: .*: (holds|MISSED)\n")
        self.assertRegex(md, rf"- bytes, case 5, C = 90%: .* \(half the text's case 4, 73, "
                             rf"x {scale:.3f}\): (holds|MISSED)\n")
        self.assertRegex(md, r"- bytes, case 5new, C = 90%: .* \(half the text's case 3, ")
        self.assertIn("time to C = 90% at 1 Mbit/s: not judged (1 Mbit/s is not among --rates)",
                      md)

    def test_bad_options_give_one_line_and_status_1(self):
        with tempfile.TemporaryDirectory() as out:
            for args, field in [(["--rates", "0"], "--rates"), (["--rates", "x"], "--rates"),
                                (["--cases", "1,8"], "--cases"),
                                (["--volume", "/nonexistent.nhdr"], "--volume")]:
                p = study("--out", out, *args)
                self.assertEqual(p.returncode, 1, args)
                lines = p.stderr.strip().splitlines()
                self.assertEqual(len(lines), 1, p.stderr)
                self.assertIn(field, lines[0])
            self.assertEqual(os.listdir(out), [])


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: remote_study_test.py PATH/TO/isowall")
    ISOWALL = sys.argv.pop(1)
    unittest.main()
