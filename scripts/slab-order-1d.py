#!/usr/bin/python3
"""One ray through a row of voxels (docs/compositing.md): the continuous emission-absorption integral
of the sum of Gaussian kernels (s_g = 0.65 voxel) against the kernel order (each kernel one sheet at
its centre; scripts/sheet-order-1d.py) and against the slab order of `--compositing slabs`: each
kernel's optical depth spread over radial slabs by its Gaussian profile along the ray (fraction
Phi((b - d)/s) - Phi((a - d)/s) for slab [a, b), d its centre), summed within each slab (tau and
tau*colour), each slab composited as one layer. Columns: the error of the kernel order, then of
slabs of 1 voxel (boundaries at half voxels, then at whole voxels), 1/2 voxel (two phases) and 1/4.
Usage: /usr/bin/python3 scripts/slab-order-1d.py   (needs python3-numpy)"""
import importlib.util
import os
from math import erf, sqrt

import numpy as np

# The kernel (S), the continuous integral, the kernel order and the cases: scripts/sheet-order-1d.py.
_spec = importlib.util.spec_from_file_location("sheet_order_1d", os.path.join(os.path.dirname(os.path.abspath(__file__)), "sheet-order-1d.py"))
sheet = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sheet)
S, continuous, sheets = sheet.S, sheet.continuous, sheet.sheets

Phi = lambda x: 0.5 * (1 + erf(x / sqrt(2)))


def sliced(sigma, colour, z0, delta, offset=0.5):
    edges = np.arange(-4.0 - offset, len(sigma) + 4, delta)
    out, T = 0.0, 1.0
    for a, b in zip(edges[:-1], edges[1:]):
        f = [Phi((b - c) / S) - Phi((a - c) / S) for c in z0]
        tau = sum(s * w for s, w in zip(sigma, f))
        em = sum(s * k * w for s, k, w in zip(sigma, colour, f))
        if tau <= 0:
            continue
        alpha = 1 - np.exp(-tau)
        out += T * alpha * em / tau
        T *= 1 - alpha
    return out


print(f"{'profile (sigma per voxel, colour)':32s} {'kernels':>8s} {'1 vox':>8s} {'1 vox@0':>8s} {'1/2':>8s} {'1/2@0':>8s} {'1/4':>8s}")
for name, sigma, colour in sheet.CASES:
    z0 = np.arange(sheet.N, dtype=float)
    c = continuous(sigma, colour, z0)
    r = [sheets(sigma, colour, z0) - c] + [sliced(sigma, colour, z0, d, o) - c
                                           for d, o in ((1, 0.5), (1, 0.0), (0.5, 0.25), (0.5, 0.0), (0.25, 0.125))]
    print(f"{name:32s} " + " ".join(f"{x:+8.4f}" for x in r))
