#!/usr/bin/python3
"""Compares the page's canvas PNG with `isowall render`'s PNG of the same view.

  compare_images.py PAGE.png REF.png [--min-iou 0.99] [--min-within2 0.9] [--diff OUT.png]

The mask of an image is its non-black pixels (the background is black). Prints the masks' IoU
and, over the pixels both masks cover, the share whose largest channel difference is within
1, 2 and 4 /255, and the mean and largest difference. Exits 1 when the IoU or the share within
2/255 is below the thresholds given.
"""
import argparse
import sys

import numpy as np
import matplotlib.image as mpimg


def load(path):
    img = mpimg.imread(path)
    if img.dtype != np.uint8:
        img = np.rint(img * 255.0).astype(np.int16)
    else:
        img = img.astype(np.int16)
    if img.ndim == 2:
        img = np.stack([img] * 3, axis=-1)
    return img[..., :3]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('page')
    ap.add_argument('ref')
    ap.add_argument('--min-iou', type=float, default=0.99)
    ap.add_argument('--min-within2', type=float, default=0.0,
                    help='least share of covered pixels within 2/255 (default 0: not checked)')
    ap.add_argument('--diff', help='write a difference image (x8) here')
    a = ap.parse_args()
    p, r = load(a.page), load(a.ref)
    if p.shape != r.shape:
        print(f'size differs: {a.page} {p.shape[1]}x{p.shape[0]}, {a.ref} {r.shape[1]}x{r.shape[0]}')
        return 1
    mp, mr = p.max(axis=-1) > 0, r.max(axis=-1) > 0
    union = np.count_nonzero(mp | mr)
    inter = mp & mr
    iou = np.count_nonzero(inter) / union if union else 1.0
    d = np.abs(p - r).max(axis=-1)[inter]
    n = max(d.size, 1)
    w1, w2, w4 = (np.count_nonzero(d <= k) / n for k in (1, 2, 4))
    print(f'pixels: page {np.count_nonzero(mp)}, ref {np.count_nonzero(mr)}, both {d.size}, '
          f'only page {np.count_nonzero(mp & ~mr)}, only ref {np.count_nonzero(mr & ~mp)}')
    print(f'IoU {iou:.5f}')
    print(f'within 1/255 {w1:.4f}  within 2/255 {w2:.4f}  within 4/255 {w4:.4f}  '
          f'mean {d.mean() if d.size else 0:.3f}  max {d.max() if d.size else 0}')
    if a.diff:
        full = np.abs(p - r).max(axis=-1)
        out = np.clip(full * 8, 0, 255).astype(np.uint8)
        mpimg.imsave(a.diff, out, cmap='magma', vmin=0, vmax=255)
    ok = iou >= a.min_iou and w2 >= a.min_within2
    if not ok:
        print(f'FAIL: IoU {iou:.5f} (min {a.min_iou}), within 2/255 {w2:.4f} (min {a.min_within2})')
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
