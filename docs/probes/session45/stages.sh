#!/bin/bash
# One-shot against warm, stage by stage (docs/performance.md, session 45): for each view, RUNS
# renders alternated between a fresh process (--warmup 0) and a render after WARM untimed ones in
# the same process (--warmup WARM: buffers kept, as VTK's timed Render() follows its warm-up), and
# the medians of `seconds`, of each `stage_seconds` entry and of `page_faults`.
# Usage (project root, after a build): docs/probes/session45/stages.sh [BIN] [RUNS] [WARM]
#   VIEWS="checkerbox:grey:1:400 engine:ct-bone:8:1024" docs/probes/session45/stages.sh
set -euo pipefail
bin=${1:-build/vdbsplat} runs=${2:-5} warm=${3:-2}
views=${VIEWS:-"checkerbox:grey:8:400 checkerbox:grey:1:400 checkerbox:grey:8:1024 engine:ct-bone:8:400 engine:ct-bone:1:400 engine:ct-bone:8:1024"}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for r in $(seq "$runs"); do
  for v in $views; do
    IFS=: read -r vol tf dist size <<<"$v"
    for w in 0 "$warm"; do
      "$bin" render "volumes/$vol.vdb" -o "$out/i.png" --tf "$tf" --threads 2 --distance "$dist" \
        --size "${size}x${size}" --tables tables --warmup "$w" --stats "$out/s.json" >/dev/null
      python3 -c "import json,sys; d=json.load(open('$out/s.json')); st=d['stage_seconds']
print('$v', $w, d['seconds']*1e3, d['page_faults'], *(st[k]*1e3 for k in ('stream','project','composite','rasterize')))" >>"$out/rows"
    done
  done
done
python3 - "$out/rows" <<'P'
import collections, statistics, sys
rows = collections.defaultdict(list)
for line in open(sys.argv[1]):
    v, w, *x = line.split()
    rows[(v, int(w))].append([float(a) for a in x])
print("| view (volume:tf:distance:size) | render | ms | page faults | stream | project | composite | rasterize | other |")
print("|---|---|---|---|---|---|---|---|---|")
for (v, w), xs in rows.items():
    m = [statistics.median(c) for c in zip(*xs)]
    kind = "one-shot" if w == 0 else f"warm (--warmup {w})"
    print(f"| {v} | {kind} | {m[0]:.1f} | {m[1]:.0f} | {m[2]:.1f} | {m[3]:.1f} | {m[4]:.1f} | {m[5]:.1f} | {m[0]-sum(m[2:]):.1f} |")
P
