#!/bin/bash
# Session 32: alternated one-shot renders of the buffer-warmer probe (buffer-warmer.patch applied,
# built in build/) in three variants — off (VDBSPLAT_NO_WARM), the default hint (64 k records and
# the frame), the hint without the frame (VDBSPLAT_WARM_NOFRAME) — printing per view the medians of
# the render's `seconds`, its page faults (--stats page_faults), the load (from the start of the
# load to the warmer's stop, VDBSPLAT_WARM_DEBUG) and the process wall time.
# usage: docs/probes/session32/warm-rounds.sh [RUNS]   (from the project root; default 11)
RUNS=${1:-11}
BIN=build/vdbsplat
VARIANTS=("off:VDBSPLAT_NO_WARM=1" "frame:X=1" "noframe:VDBSPLAT_WARM_NOFRAME=1")
for spec in "engine ct-bone 8 400" "engine ct-bone 8 1024" "checkerbox grey 8 400" "checkerbox grey 8 1024" \
            "engine ct-bone 1 400" "checkerbox grey 1 400" "checkerbox grey 1 1024" "engine ct-bone 0.35 400"; do
  set -- $spec; f=$1 tf=$2 d=$3 s=$4
  for r in $(seq "$RUNS"); do for v in "${VARIANTS[@]}"; do
    lab=${v%%:*}; envs=${v#*:}
    st=$(date +%s%N)
    env $envs VDBSPLAT_WARM_DEBUG=1 $BIN render volumes/$f.vdb --tf $tf --distance $d --size ${s}x$s \
        -o /tmp/warm.png --stats /tmp/warm.json 2>/tmp/warm.dbg
    en=$(date +%s%N)
    load=$(grep -o "load [0-9.]*" /tmp/warm.dbg | cut -d' ' -f2)
    python3 -c "import json;d=json.load(open('/tmp/warm.json'));print('$lab',d['seconds']*1000,d['page_faults'],($en-$st)/1e6,$load)"
  done; done > /tmp/warm.out
  python3 - "$spec" <<'P'
import sys, statistics as S
rows = {}
for l in open('/tmp/warm.out'):
    b, s, f, w, ld = l.split(); rows.setdefault(b, []).append((float(s), int(f), float(w), float(ld)))
cells = [f"{b} {S.median(x[0] for x in v):.1f} ms, {S.median(x[1] for x in v):.0f} faults, load {S.median(x[3] for x in v):.1f}, wall {S.median(x[2] for x in v):.1f}"
         for b, v in rows.items()]
print(f"| {sys.argv[1]} | " + " | ".join(cells) + " |")
P
done
