#!/usr/bin/env python3
"""The page faults of a process's last render only (docs/performance.md, session 47).

With docs/probes/session47/marker-between-renders.patch applied (render --warmup N touches a fresh
marker page between the renders), from the project root:
  perf record -e page-faults -c 1 --call-graph dwarf,16384 -o /tmp/pf.data \\
      build/vdbsplat render volumes/checkerbox.vdb --distance 8 --size 1024x1024 -o /tmp/c.png --warmup 1
  perf script -i /tmp/pf.data > /tmp/pf.txt
  docs/probes/session47/split-faults.py /tmp/pf.txt [TOP]
Counts the faults after the last marker by their first three vdbsplat frames, leaving out the
image writer's and the stats file's (the main thread's stacks through those; a worker thread's
PNG bands show as tbb start_for frames).
"""
import collections
import re
import sys

stacks = open(sys.argv[1]).read().split("\n\n")
marks = [i for i, s in enumerate(stacks) if "markerBetweenRenders" in s]
start = marks[-1] + 1 if marks else 0
OUTSIDE = ("readVdbGrid", "writeImage", "encodePng", "_dl_", "checkVdb", "deflate", "toJson", "writeTextFile")
counts, total = collections.Counter(), 0
for stack in stacks[start:]:
    frames = [re.sub(r"^[0-9a-f]+ ", "", l.strip()) for l in stack.strip().split("\n")[1:]]
    if not frames or any(x in f for f in frames for x in OUTSIDE):
        continue
    ours = [f.split("(")[0].split("+")[0] for f in frames if "vdbsplat::" in f]
    counts[" <- ".join(o[-60:] for o in ours[:3]) if ours else frames[0][:80]] += 1
    total += 1
print(total, "faults after the last marker")
for where, n in counts.most_common(int(sys.argv[2]) if len(sys.argv) > 2 else 30):
    print(f"{n:5d} {where}")
