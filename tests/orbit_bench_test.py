#!/usr/bin/python3
"""Tests of scripts/orbit_bench.py (interaction timed): a quick orbit of two steps on a
2x2 wall with the shared tooth prints a row of figures for each step, static and balanced, the
medians and the target's verdict, and writes orbit.csv and the plot; bad options give one line
and status 1. Skips (status 77) without ../shared/data.

Run: /usr/bin/python3 tests/orbit_bench_test.py BUILD_DIR   (CTest passes the path)
"""
import csv
import os
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "orbit_bench.py")
DATA = os.environ.get("ISOWALL_SHARED_DATA", os.path.join(os.path.dirname(ROOT), "shared", "data"))
BUILD = None


def bench(*args):
    return subprocess.run([sys.executable, SCRIPT, "--build", BUILD, "--data", DATA, *args],
                          capture_output=True, text=True, timeout=600)


class OrbitBench(unittest.TestCase):
    def test_two_steps_on_a_small_wall(self):
        with tempfile.TemporaryDirectory() as out:
            wall = os.path.join(out, "2x2.toml")
            with open(wall, "w") as f:
                f.write("tiles = [2, 2]\ntile_size_px = [160, 120]\n")
            r = bench("--volume", os.path.join(DATA, "tooth.nhdr"), "--iso", "620", "--steps",
                      "2", "--step-deg", "20", "--wall", wall, "--out", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            steps = [l for l in r.stdout.splitlines() if re.match(r"^\s+[12]\s+[0-9.]", l)]
            self.assertEqual(len(steps), 2, r.stdout)
            for row in steps:
                figures = [float(v) for v in row.split()[1:]]
                self.assertEqual(len(figures), 4, row)
                # C = 90% comes no later than C = 99%, both after the step.
                self.assertGreater(figures[0], 0, row)
                self.assertLessEqual(figures[0], figures[1], row)
                self.assertLessEqual(figures[2], figures[3], row)
            for mode in ("static", "balanced"):
                self.assertRegex(r.stdout, mode + r": median C=90% [0-9.]+ s, C=99% [0-9.]+ s: "
                                 r"[0-9.]+ views per second at C = 99%")
            self.assertRegex(r.stdout, r"at most 1/4 of static: [0-9.]+ \((holds|MISSED)\)")
            with open(os.path.join(out, "orbit.csv")) as f:
                rows = list(csv.DictReader(f))
            self.assertEqual(len(rows), 4)
            self.assertEqual({r["mode"] for r in rows}, {"static", "balanced"})
            self.assertGreater(os.path.getsize(os.path.join(out, "orbit_tooth.png")), 1000)

    def test_bad_options_are_one_line(self):
        for args, needle in ((["--steps", "1"], "--steps"),
                             (["--steps", "x"], "--steps"),
                             (["--step-deg", "0"], "--step-deg"),
                             (["--iso", "40"], "--volume and --iso"),
                             (["--volume", "/nonexistent/v.nhdr", "--iso", "1"], "--volume"),
                             (["--wall", "/nonexistent/w.toml"], "--wall")):
            r = bench(*args)
            self.assertEqual(r.returncode, 1, (args, r.stderr))
            lines = r.stderr.strip().splitlines()
            self.assertEqual(len(lines), 1, (args, r.stderr))
            self.assertIn(needle, lines[0])


if __name__ == "__main__":
    BUILD = os.path.abspath(sys.argv.pop(1)) if len(sys.argv) > 1 else os.path.join(ROOT, "build")
    if not os.path.exists(os.path.join(DATA, "tooth.nhdr")):
        print(f"skip: no shared data at {DATA}")
        sys.exit(77)
    unittest.main()
