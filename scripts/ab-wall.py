#!/usr/bin/python3
"""Whole-process wall time of two vdbsplat binaries on one command, interleaved.

Usage (from the project root):
    /usr/bin/python3 scripts/ab-wall.py OLD_BIN NEW_BIN RUNS [ARGS...]
    e.g. scripts/ab-wall.py /tmp/vdbsplat-old build/vdbsplat 150 --version
         scripts/ab-wall.py /tmp/vdbsplat-old build/vdbsplat 40 render volumes/engine.vdb \\
             --tf ct-bone --distance 8 -o /tmp/ab.png

Where scripts/ab.sh compares `seconds` (render() only), this times what a user waits for:
start-up (the dynamic loader, library initialisers), the load, the render and the write. Each
round runs both binaries, the order flipped every other round, so that drift in the machine's
load hits both alike; prints the minimum and the median of each and their ratios. ARGS defaults
to --version (start-up alone). A benchmark, not a test: compare within one run.
"""
import statistics
import subprocess
import sys
import time

if len(sys.argv) < 4:
    sys.exit(__doc__)
old, new, runs = sys.argv[1], sys.argv[2], int(sys.argv[3])
args = sys.argv[4:] or ["--version"]
times = {old: [], new: []}
for i in range(runs):
    for exe in (old, new) if i % 2 == 0 else (new, old):
        t0 = time.perf_counter()
        r = subprocess.run([exe] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        times[exe].append(time.perf_counter() - t0)
        if r.returncode != 0:
            sys.exit(f"ab-wall: {exe} failed: {r.stderr.strip()}")
lo = {exe: min(t) for exe, t in times.items()}
med = {exe: statistics.median(t) for exe, t in times.items()}
for exe in (old, new):
    print(f"{exe}: min {lo[exe] * 1e3:.1f} ms, median {med[exe] * 1e3:.1f} ms")
print(f"speed-up {lo[old] / lo[new]:.2f}x (min), {med[old] / med[new]:.2f}x (median), {runs} rounds")
