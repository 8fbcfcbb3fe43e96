#!/usr/bin/python3
"""Summary of `vdbsplat animate --reference` runs: mean flicker (all frames, frames 1-28 and 36-47
of the 48-frame Engine zoom in docs/animation.md), PSNR min/mean/max, the largest dip (how far a
frame's PSNR lies below both neighbours) and the summed render seconds, then the flicker ratios of
the first folder to the others.
Usage: /usr/bin/python3 scripts/animation-summary.py out/anim_hybrid out/anim_splat out/anim_point ..."""
import csv
import sys

res = {}
for folder in sys.argv[1:]:
    m = folder
    rows = list(csv.DictReader(open(f"{folder}/frames.csv")))
    psnr = [float(r['psnr']) for r in rows]
    fl = [float(r['flicker']) for r in rows if r['flicker']]
    dips = []
    for i in range(len(psnr)):
        nb = [psnr[j] for j in (i - 1, i + 1) if 0 <= j < len(psnr)]
        dips.append(min(nb) - psnr[i])
    far = [float(r['flicker']) for r in rows[1:29]]; close = [float(r['flicker']) for r in rows[36:]]
    res[m] = sum(fl) / len(fl)
    print(f"{m}: mean flicker {sum(fl)/len(fl):.6f} (frames 1-28 {sum(far)/len(far):.6f}, 36-47 {sum(close)/len(close):.6f}), PSNR min/mean/max {min(psnr):.2f}/{sum(psnr)/len(psnr):.2f}/{max(psnr):.2f}, largest dip {max(dips):.2f} dB (frame {dips.index(max(dips))}), render s {sum(float(r['seconds']) for r in rows):.1f}")
first = sys.argv[1]
for other in sys.argv[2:]:
    print(f"{first} / {other} mean flicker: {res[first] / res[other]:.3f}")
