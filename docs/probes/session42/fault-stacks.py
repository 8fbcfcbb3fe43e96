#!/usr/bin/env python3
"""Counts a render's page faults by where they happen (docs/performance.md, session 42).

Usage: perf record -e page-faults -c 1 --call-graph dwarf,16384 -o /tmp/pf.data build/vdbsplat render ...
       perf script -i /tmp/pf.data > /tmp/pf.txt
       docs/probes/session42/fault-stacks.py /tmp/pf.txt [TOP]

Leaves out the faults of the load, the image writer, the command line and the dynamic loader (the
stacks that pass through those functions), and groups the rest by the first vdbsplat frame of each
stack (the function whose write faulted, or the one that called the library that did).
"""
import collections
import re
import sys

OUTSIDE = ("readVdbGrid", "writeImage", "encodePng", "_dl_", "checkVdb", "settingsFromFlags",
           "addRenderFlags", "parseReindex", "parseFootprint", "deflate")

counts, total = collections.Counter(), 0
for stack in open(sys.argv[1]).read().split("\n\n"):
    frames = [re.sub(r"^[0-9a-f]+ ", "", l.strip()) for l in stack.strip().split("\n")[1:]]
    if not frames or any(x in f for f in frames for x in OUTSIDE):
        continue
    ours = [f.split("(")[0].split("+")[0] for f in frames if "vdbsplat::" in f and "lambda" not in f]
    counts[ours[0] if ours else frames[0].split("(")[0].split("+")[0]] += 1
    total += 1
print(f"{total} faults inside the render")
for where, n in counts.most_common(int(sys.argv[2]) if len(sys.argv) > 2 else 15):
    print(f"{n:6d}  {where}")
