#!/usr/bin/python3
"""The wall studies' verdicts from figures alone, without ../shared or a wall run: the mosaic
gate (scripts/mosaic_gate.py) on small PNGs at its thresholds; the load-balance study's targets
(scripts/balance_study.py) at each boundary and just past it, every figure from the rows' own
runs, and missed everywhere when the balanced mosaic is not the static one's picture; the orbit
benchmark's verdict (scripts/orbit_bench.py) at 1/4, with a step that never reaches C = 99%
counted as infinitely late and with mosaics that differ.

Run: /usr/bin/python3 tests/study_verdicts_test.py SCRATCH_DIR   (CTest passes it)
"""
import contextlib
import io
import os
import shutil
import sys
import unittest

import numpy as np
from PIL import Image

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import balance_study  # noqa: E402
import mosaic_gate  # noqa: E402
import orbit_bench  # noqa: E402

SCRATCH = None


def png(name, rgb):
    path = os.path.join(SCRATCH, name + ".png")
    Image.fromarray(np.asarray(rgb, dtype=np.uint8), "RGB").save(path)
    return path


def disc(size=100, radius=30, colour=(200, 150, 100)):
    """A filled disc on the black background: 2821 covered pixels of 10,000."""
    y, x = np.mgrid[0:size, 0:size]
    img = np.zeros((size, size, 3), dtype=np.uint8)
    img[(x - size / 2) ** 2 + (y - size / 2) ** 2 <= radius ** 2] = colour
    return img


class MosaicGate(unittest.TestCase):
    def test_the_same_picture_within_one_level(self):
        a = disc()
        b = a.astype(np.int16)
        b[a.any(axis=2)] += 1  # every covered pixel one level brighter: within 1/255
        c = mosaic_gate.compare(png("a", a), png("b", np.clip(b, 0, 255)))
        self.assertEqual(c["iou"], 1.0)
        self.assertEqual(c["equal_share"], 1.0)
        self.assertTrue(mosaic_gate.same_view(c), c)

    def test_each_threshold_at_its_boundary_and_past_it(self):
        a = disc()
        covered = int(np.count_nonzero(a.any(axis=2)))
        # Colour: 10 covered pixels of 10,000 off by 2 levels is 99.9% equal (holds); 11 is not.
        inside = np.flatnonzero(a.any(axis=2))
        for off, same in ((10, True), (11, False)):
            b = a.copy()
            b.reshape(-1, 3)[inside[:off]] += 2
            c = mosaic_gate.compare(png("a", a), png(f"off{off}", b))
            self.assertEqual(c["iou"], 1.0)
            self.assertAlmostEqual(c["equal_share"], 1 - off / 10000)
            self.assertEqual(c["max_error"], 2)
            self.assertEqual(mosaic_gate.same_view(c), same, c)
        # Coverage: an IoU just below 0.999 fails even when colours are nearly all equal.
        # 2 background pixels lit by one level: IoU covered/(covered + 2) holds above 0.999
        # only while covered >= 1998; the disc covers 2821, so 2 hold and 3 do not.
        for lit, same in ((2, True), (3, False)):
            b = a.copy()
            b.reshape(-1, 3)[:lit] = 1
            c = mosaic_gate.compare(png("a", a), png(f"lit{lit}", b))
            self.assertEqual(c["equal_share"], 1.0)
            self.assertAlmostEqual(c["iou"], covered / (covered + lit))
            self.assertEqual(mosaic_gate.same_view(c), same, c)
        self.assertFalse(mosaic_gate.same_view(c))
        self.assertIn("DIFFERS", mosaic_gate.describe(c))

    def test_mosaics_of_other_sizes_differ(self):
        c = mosaic_gate.compare(png("a", disc()), png("small", disc(size=50, radius=10)))
        self.assertFalse(mosaic_gate.same_view(c))
        self.assertIn("sizes differ: 100x100 and 50x50", mosaic_gate.describe(c))


def row(makespan, total, balance=0.9, comm_pct=5, same=True):
    return {"makespan": makespan, "total": total, "balance": balance, "comm_pct": comm_pct,
            "c99": 0.1, "same_picture": same, "picture": "mask IoU 1"}


class BalanceStudy(unittest.TestCase):
    def verdicts(self, case, static, bal):
        return {what.split(" ")[0] + " " + what.split(" ")[1]: ok
                for what, _, _, ok in balance_study.target_figures(case, static, bal)}

    def test_one_tile_at_each_boundary(self):
        # Makespan 1.5 / 0.125 = 12x; efficiency 2.25 / (24 ranks x 0.125 s) = 0.75; total CPU
        # 2.925 / 2.25 = 1.3; communication 10%: each at its limit.
        static = row(1.5, 2.25)
        v = self.verdicts("1 tile", static, row(0.125, 2.925, comm_pct=10))
        self.assertTrue(all(v.values()), v)
        v = self.verdicts("1 tile", static, row(0.1251, 2.9251, comm_pct=11))
        self.assertFalse(any(v.values()), v)

    def test_all_tiles_at_each_boundary(self):
        static = row(1.0, 10.0)
        v = self.verdicts("all tiles", static, row(0.45, 13.0, balance=0.9))
        self.assertTrue(all(v.values()), v)
        v = self.verdicts("all tiles", static, row(0.4501, 13.01, balance=0.899, comm_pct=11))
        self.assertFalse(any(v.values()), v)

    def test_totals_are_the_rows_own(self):
        # The CPU ratio is of the two kept runs' totals, whatever other runs gave.
        static, bal = row(1.0, 10.0), row(0.4, 12.0)
        static["total_median"], bal["total_median"] = 100.0, 1.0
        figures = {w: got for w, got, _, _ in balance_study.target_figures("all tiles", static,
                                                                            bal)}
        self.assertEqual(figures["total CPU balanced/static"], "1.20")

    def test_a_mosaic_that_differs_misses_every_target(self):
        static = row(1.0, 10.0)
        fast = row(0.1, 10.0, balance=1.0, comm_pct=1, same=False)
        for case in ("1 tile", "all tiles"):
            v = self.verdicts(case, static, fast)
            self.assertTrue(v and not any(v.values()), (case, v))
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            balance_study.judge_case("all tiles", static, fast, None)
        self.assertIn("not the static one's picture", out.getvalue())
        self.assertNotIn("holds", out.getvalue())
        self.assertEqual(out.getvalue().count("MISSED"), 4, out.getvalue())

    def test_a_level_never_reached_is_infinitely_late(self):
        text = ("makespan 0.5 s (CPU), total 4.0 s, balance 0.80 (mean/max)\n"
                "every thread (busy, communication, idle waits, pager): makespan 0.6 s, total "
                "5.0 s; communication 0.1 s, at most 3% of a rank's busy CPU\n"
                "scheduler: on: 10 jobs, 4 migrated, 1.5 MB\n"
                "wall-wide C = 90/99/100%: 0.2 / never / never s; final pixels 90/99/100%: "
                "0.1 / 0.3 / never s\n")
        r = balance_study.parse(text, "test")
        self.assertEqual(r["c90"], 0.2)
        self.assertEqual(r["c99"], float("inf"))
        self.assertEqual(r["px100"], float("inf"))


class OrbitBench(unittest.TestCase):
    def test_the_ratio_at_one_quarter_and_past_it(self):
        self.assertEqual(orbit_bench.verdict([1.0, 2.0, 4.0], [0.5], True), (0.25, True))
        ratio, holds = orbit_bench.verdict([2.0], [0.5001], True)
        self.assertFalse(holds)
        self.assertAlmostEqual(ratio, 0.25005)

    def test_pictures_that_differ_miss(self):
        self.assertEqual(orbit_bench.verdict([1.0], [0.1], False), (0.1, False))

    def test_steps_that_never_arrive_are_counted_late(self):
        never = orbit_bench.seconds("never")
        self.assertEqual(never, float("inf"))
        # Two of three balanced steps never reach C = 99%: the median is never, missed.
        ratio, holds = orbit_bench.verdict([1.0, 1.0, 1.0], [0.1, never, never], True)
        self.assertFalse(holds)
        self.assertEqual(ratio, float("inf"))
        # One of three: the median is still a time (the step is counted, not dropped).
        ratio, holds = orbit_bench.verdict([1.0, 1.0, 1.0], [0.1, 0.2, never], True)
        self.assertEqual((ratio, holds), (0.2, True))
        # Neither wall arrives: missed.
        self.assertFalse(orbit_bench.verdict([never], [never], True)[1])


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: study_verdicts_test.py SCRATCH_DIR")
    SCRATCH = sys.argv[1]
    del sys.argv[1:2]
    shutil.rmtree(SCRATCH, ignore_errors=True)
    os.makedirs(SCRATCH)
    unittest.main()
