#!/usr/bin/python3
"""One ray through a row of voxels (docs/shading.md): the continuous emission-absorption integral
of the sum of Gaussian kernels (s_g = 0.65 voxel, the reference's field) against compositing each
kernel as one sheet at its centre (the forward modes), and against two half-sheets per kernel at
±s_g·sqrt(2/π). Prints the sheet error for a lit first voxel in front of unlit ones and a few
other colour profiles. Usage: /usr/bin/python3 scripts/sheet-order-1d.py   (needs python3-numpy)"""
import numpy as np

S = 0.65  # kernel standard deviation, voxels


def continuous(sigma, colour, z0):
    z = np.linspace(-4.0, len(sigma) + 4.0, 20001)
    dz = z[1] - z[0]
    g = lambda u: np.exp(-u * u / (2 * S * S)) / (S * np.sqrt(2 * np.pi))
    ext = sum(s * g(z - c) for s, c in zip(sigma, z0))
    em = sum(s * k * g(z - c) for s, k, c in zip(sigma, colour, z0))
    transmittance = np.exp(-(np.cumsum(ext) * dz - ext * dz))
    return float(np.sum(transmittance * em * dz))


def sheets(sigma, colour, z0, halves=False):
    items = []
    for s, k, c in zip(sigma, colour, z0):
        if halves:
            d = S * np.sqrt(2 / np.pi)
            items += [(c - d, s / 2, k), (c + d, s / 2, k)]
        else:
            items.append((c, s, k))
    out, T = 0.0, 1.0
    for _, tau, k in sorted(items):
        alpha = 1 - np.exp(-tau)
        out += T * alpha * k
        T *= 1 - alpha
    return out


N = 10  # voxels along the ray
CASES = [("uniform colour 1", [0.5] * N, [1.0] * N),
         ("lit first voxel 0.5, then 1", [0.5] * N, [0.5] + [1.0] * (N - 1)),
         ("two lit voxels 0.5, then 1", [0.5] * N, [0.5, 0.5] + [1.0] * (N - 2)),
         ("specular first voxel 1.2", [0.5] * N, [1.2] + [1.0] * (N - 1)),
         ("dense 1 then thin 0.3", [0.5] * 5 + [0.15] * 5, [1.0] * 5 + [0.3] * 5),
         ("thin 0.3 then dense 1", [0.15] * 5 + [0.5] * 5, [0.3] * 5 + [1.0] * 5),
         ("lit first, dense 2", [2.0] * N, [0.5] + [1.0] * (N - 1))]

if __name__ == "__main__":
    print(f"{'profile (sigma per voxel, colour)':34s} {'continuous':>10s} {'sheet error':>12s} {'half-sheets':>12s}")
    for name, sigma, colour in CASES:
        z0 = np.arange(N, dtype=float)
        c = continuous(sigma, colour, z0)
        print(f"{name:34s} {c:10.4f} {sheets(sigma, colour, z0) - c:+12.4f} {sheets(sigma, colour, z0, True) - c:+12.4f}")
