#!/usr/bin/python3
"""Session 17's check of transfer-function-independent level-of-detail sums (docs/performance.md):
what fraction of the Engine's visible 2³, 4³, 8³ cells lie within one linear piece of ct-bone
(their values between the same two knots of its extinction and colour), the only cells whose
energy such sums would give exactly.

Usage (needs python3-numpy): /usr/bin/python3 scripts/lod-linear-cells.py
"""
import gzip
import os
import sys

import numpy as np

RAW = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "volumes",
                   "engine_256x256x128_uint8.raw.gz")
if not os.path.exists(RAW):
    sys.exit(f"lod-linear-cells: {RAW} absent (../shared/volumes)")
a = np.frombuffer(gzip.open(RAW).read(), np.uint8).reshape(128, 256, 256).astype(np.float32) / 255
# ct-bone's knots (src/volume/transfer_function.cpp): extinction and colour
knots = np.array(sorted(set([0, .12, .2, .35, .5, .62, .75, 1] + [0, .12, .25, .45, .62, .75, 1])))
for side in (2, 4, 8):
    s = tuple((n // side) * side for n in a.shape)
    b = a[:s[0], :s[1], :s[2]].reshape(s[0] // side, side, s[1] // side, side, s[2] // side, side)
    mn = b.min(axis=(1, 3, 5))
    mx = b.max(axis=(1, 3, 5))
    visible = mx > 0.12  # ct-bone is transparent below 0.12
    linear = np.searchsorted(knots, mn, side="right") == np.searchsorted(knots, mx, side="left")
    print(f"{side}^3 cells: {mn.size}, visible {visible.sum()}, in one linear piece {(linear & visible).sum()} "
          f"({(linear & visible).sum() / max(1, visible.sum()):.0%} of the visible)")
