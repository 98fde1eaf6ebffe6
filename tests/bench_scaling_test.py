#!/usr/bin/python3
"""Tests of scripts/bench_scaling.py: a quick run on the shared tooth (half and full size, a small
screen) writes its table, JSON and plot, with the peer's hit pixels agreeing with our covered
pixels; bad options give one line and status 1. Skips (status 77) without ../shared/data.

Run: /usr/bin/python3 tests/bench_scaling_test.py BUILD_DIR   (CTest passes the path)
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "bench_scaling.py")
DATA = os.environ.get("ISOWALL_SHARED_DATA", os.path.join(os.path.dirname(ROOT), "shared", "data"))
TOOTH = os.path.join(DATA, "tooth.nhdr")
BUILD = None
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def bench(*args):
    return subprocess.run([sys.executable, SCRIPT, "--build", BUILD, *args],
                          capture_output=True, text=True, timeout=600)


class BenchScaling(unittest.TestCase):
    def assertMeasuredRatio(self, value, context):
        """A speed-up the bench printed: a positive finite number; its size is the bench's to report."""
        self.assertTrue(isinstance(value, (int, float)) and math.isfinite(value) and value > 0, context)

    def test_quick_run_writes_table_json_and_plot(self):
        with tempfile.TemporaryDirectory() as out:
            p = bench("--volume", TOOTH, "--iso", "620", "--scales", "0.5,1", "--size", "320x240",
                      "--out", out)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(os.path.join(out, "scaling.json")) as f:
                res = json.load(f)
            scales = res["scales"]
            self.assertEqual(res["meta"]["frame"], "warm")  # every program timed after a warm-up
            self.assertEqual([s["scale"] for s in scales], [0.5, 1])
            self.assertEqual(scales[1]["sizes"], [103, 94, 161])
            self.assertEqual(scales[0]["sizes"], [52, 47, 80])
            for s in scales:
                prog, full = s["progressive"], s["full"]
                times = [prog[k] for k in ("c90", "c99", "c999", "c100")]
                self.assertTrue(all(t is not None for t in times), s)
                self.assertEqual(times, sorted(times), s)
                self.assertLessEqual(prog["c100"], prog["every_ray_s"] + 1e-9)
                self.assertGreater(full["covered_px"], 1000)
                self.assertGreater(prog["triangles_c99"], 0)
                # The progressive final image is the full surface's (the engine's own thresholds).
                self.assertLess(abs(prog["covered_px"] - full["covered_px"]), 0.01 * full["covered_px"])
                if "skipped" not in s["peer"]:
                    # Same view, same surface: hit pixels within a fraction of a percent.
                    self.assertLess(abs(s["peer"]["hit_px"] - full["covered_px"]), 0.005 * full["covered_px"])
                    self.assertEqual(s["peer"]["triangles"], full["triangles"])
                    self.assertGreater(s["peer"]["first_total_s"], 0)  # the peer ran twice
                    # ... and once on one thread, for its own two-thread gain.
                    self.assertEqual(s["peer_1t"]["triangles"], s["peer"]["triangles"])
                    self.assertGreater(s["peer_1t"]["total_s"], 0)
                # What the machine's cores gave two threads of plain work at the time. A ratio of two
                # timings on a shared machine says nothing a test may assert beyond being measured:
                # CI saw 0.02 when other tests held both cores.
                for key in ("alu_speedup", "memory_speedup"):
                    self.assertMeasuredRatio(s["cores"][key], s["cores"])
                # Every configuration ran, and each final image was measured against the full surface.
                self.assertEqual(list(s["engines"]), ["lod-facing-2t", "lod-facing", "full-res", "facing", "lod",
                                                      "lod-refine"])
                self.assertEqual(prog, s["engines"]["lod-facing-2t"])
                self.assertGreater(s["engines"]["full-res"]["c_vs_full"], 0.99, s)
                for e in s["engines"].values():
                    self.assertGreater(e["c_vs_full"], 0.9, e)
                # The default two pair rounds: lod-facing and lod-facing-2t ran once more each
                # time (one thread first, then two threads first), each round with a machine check.
                self.assertEqual(len(s["engines"]["lod-facing"]["runs"]), 3)
                self.assertEqual(len(s["engines"]["lod-facing-2t"]["runs"]), 3)
                self.assertEqual(len(s["engines"]["lod"]["runs"]), 1)
                rounds = s["pair_rounds"]
                self.assertEqual([k["round"] for k in rounds], [1, 2, 3])
                self.assertIsNone(rounds[0]["machine"])
                for k in rounds:
                    self.assertMeasuredRatio(k["c99_speedup"], k)
                    self.assertMeasuredRatio(k["every_ray_speedup"], k)
                for k in rounds[1:]:
                    self.assertMeasuredRatio(k["machine"]["memory_speedup"], k)
                fastest_c99 = min(r["c99"] for r in s["engines"]["lod-facing-2t"]["runs"])
                self.assertEqual(s["engines"]["lod-facing-2t"]["c99"], fastest_c99)
            names = {c["target"] for c in res["targets"]}
            self.assertIn("triangles by C=99% per covered pixel", names)
            self.assertIn("every ray / our --full", names)
            self.assertIn("2 threads / 1 thread on C=99% (lod-facing)", names)
            self.assertIn("growth of C=99%, scale 1 -> 4", names)
            with open(os.path.join(out, "scaling.md")) as f:
                md = f.read()
            self.assertIn("| 103x94x161 | 1.56 M |", md)
            self.assertIn("| 52x47x80 |", md)
            self.assertIn("Targets:", md)
            self.assertIn("Two threads against one", md)
            self.assertIn("round by round", md)
            self.assertIn("median of rounds", md)
            self.assertIn("| 103x94x161 | 3 |", md)
            self.assertIn("| 103x94x161 | lod-refine |", md)
            self.assertTrue("holds" in md or "MISSED" in md)
            self.assertIn(md.splitlines()[0], p.stdout)
            with open(os.path.join(out, "scaling.png"), "rb") as f:
                self.assertEqual(f.read(8), PNG_MAGIC)

    def test_bad_options_give_one_line_and_status_1(self):
        with tempfile.TemporaryDirectory() as out:
            for args, field in [(["--scales", "0"], "--scales"), (["--scales", "1,x"], "--scales"),
                                (["--size", "320"], "--size"), (["--runs", "0"], "--runs"), (["--pair-rounds", "-1"], "--pair-rounds"),
                                (["--iso", "nan"], "--iso"), (["--runs", "x"], "--runs"),
                                (["--engines", "lod,fast"], "--engines"), (["--engines", "lod,lod"], "--engines"),
                                (["--volume", "/nonexistent.nhdr"], "--volume"),
                                (["--build", "/nonexistent"], "--build")]:
                p = subprocess.run([sys.executable, SCRIPT, "--out", out, *(["--build", BUILD] if "--build" not in args else []), *args],
                                   capture_output=True, text=True, timeout=60)
                self.assertEqual(p.returncode, 1, args)
                lines = p.stderr.strip().splitlines()
                self.assertEqual(len(lines), 1, p.stderr)
                self.assertIn(field, lines[0])
            self.assertEqual(os.listdir(out), [])


class Cores(unittest.TestCase):
    """bench/cores' isowall-cores, which the benchmark runs: --help, and one line for a bad option."""

    def test_help_and_bad_option(self):
        cores = os.path.join(BUILD, "bench", "cores", "isowall-cores")
        p = subprocess.run([cores, "--help"], capture_output=True, text=True, timeout=60)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("Usage: isowall-cores", p.stdout)
        for args in (["--reps", "x"], ["--reps"], ["--fast"]):
            p = subprocess.run([cores, *args], capture_output=True, text=True, timeout=60)
            self.assertEqual(p.returncode, 1, args)
            self.assertEqual(len(p.stderr.strip().splitlines()), 1, p.stderr)
            self.assertEqual(p.stdout, "")


if __name__ == "__main__":
    BUILD = sys.argv.pop(1)
    if not os.path.exists(TOOTH):
        print(f"bench_scaling_test: skipped: {TOOTH} not found (../shared/data or $ISOWALL_SHARED_DATA)")
        sys.exit(77)
    unittest.main()
