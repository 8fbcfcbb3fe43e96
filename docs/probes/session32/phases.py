"""Session 32: where a one-shot `vdbsplat render` process spends its wall time, by phase.

Needs binaries built with docs/probes/session32/phases.patch applied (it prints `phase NAME
MILLISECONDS MINOR_FAULTS` on stderr at each phase when VDBSPLAT_PHASES is set). Renders each
view RUNS times per binary, alternated, and prints per view and binary the median milliseconds of
each phase: start→parsed (process start-up and flags), parsed→loaded (the file), loaded→rendered
(camera, render), rendered→written (the image file), returning→exited (teardown).

usage: python3 docs/probes/session32/phases.py RUNS BIN[,BIN...] VOLUME:TF:DISTANCE:SIZE ...
"""
import os, statistics as S, subprocess, sys, time

runs, binaries, views = int(sys.argv[1]), sys.argv[2].split(','), sys.argv[3:]
keys = ['start', 'parsed', 'loaded', 'rendered', 'written', 'returning', 'exited']
env = dict(os.environ, VDBSPLAT_PHASES='1')
for view in views:
    vol, tf, dist, size = view.split(':')
    rows = {b: [] for b in binaries}
    for _ in range(runs):
        for b in binaries:
            start = time.time() * 1e3
            p = subprocess.run([b, 'render', f'volumes/{vol}.vdb', '--tf', tf, '--distance', dist, '--size',
                                f'{size}x{size}', '-o', '/tmp/phases.png'], env=env, capture_output=True, text=True, check=True)
            r = {'start': start, 'exited': time.time() * 1e3}
            for line in p.stderr.splitlines():
                w = line.split()
                if len(w) >= 3 and w[0] == 'phase': r[w[1]] = float(w[2])
            rows[b].append(r)
    for b, rs in rows.items():
        cells = ', '.join(f'{a}→{c} {S.median(r[c] - r[a] for r in rs):.1f}' for a, c in zip(keys, keys[1:]))
        print(f'| {vol} {dist} {size}² | {os.path.basename(b)} | {cells} | {S.median(r["exited"] - r["start"] for r in rs):.1f} |')
