#!/usr/bin/python3
"""Session 24's check of the exact index from the affine one (docs/performance.md, "Considered and
not built: the exact index from the affine one"): for a kernel sphere (centre c, radius r) seen
through a pinhole of focal length f, the exact d² = |c × v|² / (r² |v|²) of a pixel's ray v equals
1 − (1 − i²)·κ / |v|², with i² the pixel's index in the silhouette ellipse's conic (DESIGN §2) and
κ = |v0|² − |c × v0|² / r² at the ellipse's centre (ray v0). Prints the largest difference over
random spheres and random pixels inside their ellipses.

Usage (needs python3-numpy): /usr/bin/python3 scripts/exact-index-identity.py
"""
import numpy as np

rng = np.random.default_rng(1)
f = 500.0
worst, pixels = 0.0, 0
for _ in range(2000):
    c = np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(4, 30)])
    r = rng.uniform(0.2, 1.5)
    D, rho = np.linalg.norm(c), np.hypot(c[0], c[1])
    theta, sin_a = np.arctan2(rho, c[2]), r / D
    den = np.cos(theta) ** 2 - sin_a ** 2
    if den <= 0:
        continue
    u = np.array([c[0], -c[1]]) / rho  # image axes: x right, y down
    w = np.array([-u[1], u[0]])
    centre = u * f * np.sin(theta) * np.cos(theta) / den  # from the principal point (DESIGN §2)
    a, b = f * sin_a * np.sqrt(1 - sin_a ** 2) / den, f * sin_a / np.sqrt(den)
    Q = np.outer(u, u) / a ** 2 + np.outer(w, w) / b ** 2
    ray = lambda p: np.array([p[0] / f, -p[1] / f, 1.0])
    v0 = ray(centre)
    kappa = v0 @ v0 - np.cross(c, v0) @ np.cross(c, v0) / r ** 2
    for _ in range(20):
        t, s = rng.uniform(0, 2 * np.pi), np.sqrt(rng.uniform(0, 1))
        p = centre + s * (u * a * np.cos(t) + w * b * np.sin(t))
        delta = p - centre
        i2 = delta @ Q @ delta
        v = ray(p)
        exact = np.cross(c, v) @ np.cross(c, v) / (v @ v) / r ** 2
        worst = max(worst, abs(exact - (1 - (1 - i2) * kappa / (v @ v))))
        pixels += 1
print(f"{pixels} pixels: max |exact d² − (1 − (1 − i²)·κ/|v|²)| = {worst:.3g}")
