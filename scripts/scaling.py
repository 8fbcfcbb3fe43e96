#!/usr/bin/python3
"""Render time against active voxels and against image size: hybrid, splat-only, point-only.

Usage (from the project root, after scripts/build.sh):
    /usr/bin/python3 scripts/scaling.py [--voxels 1e5,1e6,1e7] [--sizes 400,1024,2048]
        [--size-voxels 1e6] [--runs 1] [--out out/scaling] [--plot docs/images/scaling.png]

Generates `vdbsplat generate cloud --active N` volumes (cached in --out), renders each at the
default framing with --tf fire, and records the stats `seconds` (render only, load excluded).
Writes scaling.csv, and a PNG plot when python3-matplotlib is installed (log-log, one line per
mode). A benchmark, not a test: compare the lines of one run, not absolute seconds.
"""
import argparse
import csv
import json
import os
import subprocess
import sys

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--bin", default="build/vdbsplat")
ap.add_argument("--voxels", default="1e5,1e6,1e7")
ap.add_argument("--sizes", default="400,1024,2048")
ap.add_argument("--size-voxels", default="1e6", help="the cloud rendered at every --sizes")
ap.add_argument("--voxel-size", default="1024", help="image side for the --voxels sweep")
ap.add_argument("--modes", default="hybrid,splat,point")
ap.add_argument("--runs", type=int, default=1, help="renders per point (the minimum is kept)")
ap.add_argument("--out", default="out/scaling")
ap.add_argument("--plot", default="docs/images/scaling.png")
a = ap.parse_args()
os.makedirs(a.out, exist_ok=True)


def cloud(n):
    path = os.path.join(a.out, f"cloud_{n}.vdb")
    if not os.path.exists(path):
        subprocess.run([a.bin, "generate", "cloud", "--active", str(n), "-o", path], check=True,
                       stdout=subprocess.DEVNULL)
    return path


def render(vdb, mode, side):
    stats = os.path.join(a.out, "stats.json")
    best = None
    for _ in range(a.runs):
        subprocess.run([a.bin, "render", vdb, "-o", os.path.join(a.out, "frame.png"), "--mode", mode, "--tf", "fire",
                        "--size", f"{side}x{side}", "--stats", stats], check=True, stdout=subprocess.DEVNULL)
        s = json.load(open(stats))
        best = s if best is None or s["seconds"] < best["seconds"] else best
    return best


rows = []
modes = a.modes.split(",")
for n in [int(float(x)) for x in a.voxels.split(",")]:
    vdb = cloud(n)
    for mode in modes:
        s = render(vdb, mode, int(a.voxel_size))
        rows.append({"sweep": "voxels", "active_voxels": s["active_voxels"], "size": int(a.voxel_size), "mode": mode,
                     "seconds": s["seconds"], "points": s["points"], "splats": s["splats"]})
        print(f"voxels {s['active_voxels']:>11} size {a.voxel_size:>5} {mode:>6}: {s['seconds']:.3f} s", flush=True)
vdb = cloud(int(float(a.size_voxels)))
for side in [int(x) for x in a.sizes.split(",")]:
    for mode in modes:
        s = render(vdb, mode, side)
        rows.append({"sweep": "size", "active_voxels": s["active_voxels"], "size": side, "mode": mode,
                     "seconds": s["seconds"], "points": s["points"], "splats": s["splats"]})
        print(f"voxels {s['active_voxels']:>11} size {side:>5} {mode:>6}: {s['seconds']:.3f} s", flush=True)

with open(os.path.join(a.out, "scaling.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.exit("scaling: wrote scaling.csv; apt-get install python3-matplotlib for the plot")
fig, axes = plt.subplots(1, 2, figsize=(10, 4))
for ax, sweep, key, label in [(axes[0], "voxels", "active_voxels", f"active voxels ({a.voxel_size}² image)"),
                              (axes[1], "size", "size", f"image side, pixels ({a.size_voxels} voxels)")]:
    for mode in modes:
        pts = sorted((r[key], r["seconds"]) for r in rows if r["sweep"] == sweep and r["mode"] == mode)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=mode)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(label)
    ax.set_ylabel("render seconds (2 threads)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
fig.suptitle("vdbsplat render time, generated noise cloud, default framing, --tf fire")
fig.tight_layout()
os.makedirs(os.path.dirname(a.plot) or ".", exist_ok=True)
fig.savefig(a.plot, dpi=90)
print(f"scaling: wrote {a.plot}")
