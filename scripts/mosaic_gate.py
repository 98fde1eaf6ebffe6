"""Whether two mosaics of one view are the same picture, by the rule the wall's mosaic tests use
(tests/wall_inproc_test.cpp, expect_same_view): coverage IoU at least 0.999, a pixel covered where
its RGB is not the black background, and at least 99.9% of pixels within 1/255 in every channel.

The balanced wall's speed verdicts (scripts/balance_study.py, scripts/orbit_bench.py) hold only
where its mosaic passes this against the static wall's mosaic of the same runs: a balanced wall
that is fast because it draws a different picture has no speed to report.
"""
import numpy as np
from PIL import Image

MIN_IOU = 0.999
MIN_EQUAL_SHARE = 0.999
CHANNEL_TOLERANCE = 1


def read_rgb(path):
    with Image.open(path) as img:
        return np.asarray(img.convert("RGB"), dtype=np.int16)


def compare(a_path, b_path):
    """The figures of the rule for two PNG files: mask IoU, the share of pixels within
    CHANNEL_TOLERANCE, and the largest channel error; None for IoU when the sizes differ."""
    a, b = read_rgb(a_path), read_rgb(b_path)
    if a.shape != b.shape:
        return {"iou": None, "equal_share": 0.0, "max_error": 255,
                "why": f"sizes differ: {a.shape[1]}x{a.shape[0]} and {b.shape[1]}x{b.shape[0]}"}
    covered_a, covered_b = a.any(axis=2), b.any(axis=2)
    either = int(np.count_nonzero(covered_a | covered_b))
    both = int(np.count_nonzero(covered_a & covered_b))
    error = np.abs(a - b).max(axis=2)
    differing = int(np.count_nonzero(error > CHANNEL_TOLERANCE))
    return {"iou": both / either if either else 1.0,
            "equal_share": 1.0 - differing / error.size if error.size else 1.0,
            "max_error": int(error.max()) if error.size else 0, "why": ""}


def same_view(c):
    return c["iou"] is not None and c["iou"] >= MIN_IOU and c["equal_share"] >= MIN_EQUAL_SHARE


def describe(c):
    if c["iou"] is None:
        return c["why"]
    return (f"mask IoU {c['iou']:.4f}, {100 * c['equal_share']:.2f}% of pixels within "
            f"{CHANNEL_TOLERANCE}/255 (largest error {c['max_error']}): "
            f"{'the same picture' if same_view(c) else 'DIFFERS'}")
