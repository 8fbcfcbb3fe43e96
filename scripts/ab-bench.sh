#!/usr/bin/env bash
# Warm renders of several vdbsplat binaries, alternated round by round: `vdbsplat bench` (buffers
# and level-of-detail sums kept between runs, as animate and study render), one view per volume,
# the minimum of RUNS runs per round. Prints a line per (round, binary, volume) — the minimum,
# the median and each stage's median (ms) — then, per (volume, binary), the minimum, lower
# quartile and median over the rounds and the minimum's ratio to the first binary's. On a noisy
# host read the minima and quartiles: a round that a co-tenant slowed shows as an outlier, not as
# a shift (docs/performance.md, session 41). Render time only; images are not compared
# (scripts/ab.sh does, for one-shot renders).
# Usage: scripts/ab-bench.sh DISTANCE ROUNDS BIN... [-- bench flags...]
#   e.g. scripts/ab-bench.sh 1 6 /tmp/vdbsplat-old build/vdbsplat
#        scripts/ab-bench.sh 8 4 /tmp/old build/vdbsplat -- --size 1024x1024 --threads 2
# Volumes: VOLUMES="engine:ct-bone checkerbox:grey" (volumes/NAME.vdb with its --tf), the default.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 3 ] || { echo "usage: $0 DISTANCE ROUNDS BIN... [-- bench flags...]" >&2; exit 2; }
distance=$1 rounds=$2
shift 2
bins=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do bins+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
flags=("$@")
volumes=${VOLUMES:-"engine:ct-bone checkerbox:grey"}
runs=${RUNS:-7}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for r in $(seq "$rounds"); do
  for b in "${bins[@]}"; do
    for v in $volumes; do
      f=${v%%:*} tf=${v##*:}
      [ -f "volumes/$f.vdb" ] || { echo "ab-bench: volumes/$f.vdb absent (volumes/fetch.sh, volumes/make-generated.sh)" >&2; exit 1; }
      "$b" bench "volumes/$f.vdb" --tf "$tf" --distances "$distance" --modes hybrid --runs "$runs" --threads 1 \
        --tables tables --json "$tmp/b.json" "${flags[@]}" >/dev/null
      python3 - "$tmp/b.json" "$r" "$b" "$f" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))["results"][0]
stages = " ".join(f"{k}={v * 1e3:.2f}" for k, v in sorted(j["stages"].items()))
print(sys.argv[2], sys.argv[3], sys.argv[4], f"{j['min_seconds'] * 1e3:.2f}", f"{j['median_seconds'] * 1e3:.2f}", stages)
PY
    done
  done
done | tee "$tmp/rows.txt"
python3 - "$tmp/rows.txt" "${bins[@]}" <<'PY'
import collections, sys
rows = [l.split() for l in open(sys.argv[1])]
bins = sys.argv[2:]
by = collections.defaultdict(list)
for r in rows:
    by[(r[2], r[1])].append(float(r[3]))
print("\nvolume binary: minima over rounds — min / q25 / median (ms), min ratio to the first binary")
for vol in dict.fromkeys(r[2] for r in rows):
    base = min(by[(vol, bins[0])])
    for b in bins:
        v = sorted(by[(vol, b)])
        print(f"{vol} {b}: {v[0]:.1f} / {v[len(v) // 4]:.1f} / {v[len(v) // 2]:.1f}  ({v[0] / base:.3f})")
PY
