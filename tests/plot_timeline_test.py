#!/usr/bin/python3
"""Tests of scripts/plot_timeline.py: run it as a user would, on small CSVs written here.

Run: /usr/bin/python3 tests/plot_timeline_test.py   (not part of CTest)
"""
import math
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "plot_timeline.py")
HEADER = ("time_s,rays,rays_share,cells_visited,triangles,groups,final_pixels,c,"
          "t_intersect_s,t_propagate_s,t_extract_s,t_render_s")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def synthetic_rows(count, c_of_t=lambda t: 1 - math.exp(-t)):
    rows = []
    for k in range(count):
        t = 0.1 * k
        c = c_of_t(t)
        rows.append(f"{t:.2f},{1000 * k},{min(1, t / 3):.4f},{5000 * k},{2000 * k},{4 * k},"
                    f"{max(0.0, c - 0.05):.5f},{c:.5f},{0.3 * t:.4f},{0.1 * t:.4f},"
                    f"{0.4 * t:.4f},{0.1 * t:.4f}")
    return rows


class PlotTimeline(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)

    def write(self, text, name="timeline.csv"):
        path = os.path.join(self.tmp.name, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def assert_png(self, path):
        with open(path, "rb") as f:
            self.assertEqual(f.read(8), PNG_MAGIC, path)

    def test_writes_both_plots_and_the_table(self):
        path = self.write("\n".join([HEADER + ",unknown"] +
                                    [r + ",x" for r in synthetic_rows(80)]) + "\n")
        prefix = os.path.join(self.tmp.name, "out")
        result = self.run_script(path, "--out", prefix, "--title", "test")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assert_png(prefix + "_progress.png")
        self.assert_png(prefix + "_stages.png")
        # 1 - exp(-t) first reaches 0.90 at t = ln 10 = 2.30..., i.e. the sample at 2.4 s.
        line = next(l for l in result.stdout.splitlines() if l.startswith("C >= 90%"))
        self.assertEqual(line.split()[3:6], ["2.400", "48000", "24000"], result.stdout)
        self.assertIn("last row", result.stdout)

    def test_default_prefix_is_the_csv_path(self):
        path = self.write("\n".join([HEADER] + synthetic_rows(5)) + "\n", "run7.csv")
        result = self.run_script(path)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assert_png(os.path.join(self.tmp.name, "run7_progress.png"))
        self.assert_png(os.path.join(self.tmp.name, "run7_stages.png"))

    def test_thresholds_never_reached(self):
        path = self.write("\n".join([HEADER] + synthetic_rows(10, lambda t: 0.5 * t)) + "\n")
        result = self.run_script(path, "--out", os.path.join(self.tmp.name, "o"))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.count("not reached"), 6, result.stdout)

    def test_single_row(self):
        path = self.write("\n".join([HEADER] + synthetic_rows(2)[1:]) + "\n")
        prefix = os.path.join(self.tmp.name, "one")
        for extra in ([], ["--logx"]):
            result = self.run_script(path, "--out", prefix, *extra)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assert_png(prefix + "_progress.png")
            self.assert_png(prefix + "_stages.png")

    def test_logx_with_a_sample_at_time_zero(self):
        path = self.write("\n".join([HEADER] + synthetic_rows(30)) + "\n")
        result = self.run_script(path, "--logx", "--out", os.path.join(self.tmp.name, "log"))
        self.assertEqual(result.returncode, 0, result.stderr)

    def test_missing_column_is_one_line_naming_file_and_column(self):
        header = HEADER.replace("t_render_s", "t_draw_s")
        path = self.write("\n".join([header] + synthetic_rows(3)) + "\n")
        result = self.run_script(path)
        self.assertEqual(result.returncode, 1)
        self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)
        self.assertIn(path, result.stderr)
        self.assertIn("t_render_s", result.stderr)

    def test_empty_file_and_header_only(self):
        for text in ["", HEADER + "\n"]:
            path = self.write(text)
            result = self.run_script(path)
            self.assertEqual(result.returncode, 1, repr(text))
            self.assertIn(path, result.stderr)
            self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)

    def test_bad_number_names_line_and_column(self):
        rows = synthetic_rows(3)
        fields = rows[1].split(",")
        fields[7] = "abc"
        rows[1] = ",".join(fields)
        path = self.write("\n".join([HEADER] + rows) + "\n")
        result = self.run_script(path)
        self.assertEqual(result.returncode, 1)
        self.assertIn("line 3", result.stderr)
        self.assertIn("'c'", result.stderr)

    def test_missing_file(self):
        result = self.run_script(os.path.join(self.tmp.name, "nope.csv"))
        self.assertEqual(result.returncode, 1)
        self.assertIn("nope.csv", result.stderr)

    def test_help(self):
        result = self.run_script("--help")
        self.assertEqual(result.returncode, 0)
        self.assertIn("--logx", result.stdout)
        self.assertIn("final_pixels", result.stdout)


if __name__ == "__main__":
    unittest.main()
