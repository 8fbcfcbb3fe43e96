#!/usr/bin/python3
"""docs/images/animation_engine_lod_blend.svg: per-frame flicker and PSNR of the 48-frame Engine zoom
(docs/animation.md, session 5) for hybrid with session 4's switching level of detail, hybrid with the
blended one, splat-only and hybrid --lod 0, from the frames.csv copies in docs/images/.
Usage: /usr/bin/python3 scripts/animation-lod-plot.py [OUT.svg]"""
import csv
import os
import sys

import matplotlib
matplotlib.use('svg')
import matplotlib.pyplot as plt

plt.rcParams['svg.fonttype'] = 'none'
plt.rcParams['svg.hashsalt'] = 'vdbsplat'
images = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'docs', 'images')
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(images, 'animation_engine_lod_blend.svg')
runs = [('hybrid, session 4 (levels switch)', 'animation_engine_hybrid_session4.csv', '#d62728', '-'),
        ('hybrid, blended levels (session 5)', 'animation_engine_hybrid_session5.csv', '#1f77b4', '-'),
        ('splat-only', 'animation_engine_splat_session5.csv', '#2ca02c', '--'),
        ('hybrid --lod 0', 'animation_engine_hybrid_lod0_session5.csv', '#7f7f7f', ':')]
fig, (a, b) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
for name, f, colour, style in runs:
    rows = list(csv.DictReader(open(os.path.join(images, f))))
    frames = [int(r['frame']) for r in rows]
    a.plot(frames[1:], [float(r['flicker']) for r in rows[1:]], color=colour, ls=style, label=name)
    b.plot(frames, [float(r['psnr']) for r in rows], color=colour, ls=style, label=name)
a.set_ylabel('flicker F_t')
b.set_ylabel('PSNR vs reference (dB)')
b.set_xlabel('frame (distance 8 → 0.125)')
a.legend(fontsize=8)
a.grid(alpha=.3)
b.grid(alpha=.3)
a.set_title('Engine zoom, 160², reference spp 4: level of detail switching vs blended')
fig.tight_layout()
fig.savefig(out, metadata={'Date': None})
