#!/usr/bin/env bash
# Before/after render time of two vdbsplat binaries on one view, alternating runs so that machine
# noise hits both alike; prints the minimum `seconds` (render only, from --stats) of each, the
# ratio, and `compare` of the two images (rmse 0: identical).
# Usage: scripts/ab.sh OLD_BIN NEW_BIN RUNS FILE.vdb [render flags...]
#   e.g. scripts/ab.sh /tmp/vdbsplat-old build/vdbsplat 5 out/engine.vdb --tf ct-bone --distance 1
set -euo pipefail
[ $# -ge 4 ] || { echo "usage: $0 OLD_BIN NEW_BIN RUNS FILE.vdb [render flags...]" >&2; exit 2; }
old=$1 new=$2 runs=$3 vdb=$4
shift 4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
seconds() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['seconds'])" "$1"; }
best_old=inf best_new=inf
for _ in $(seq "$runs"); do
  "$old" render "$vdb" -o "$tmp/old.png" --stats "$tmp/old.json" "$@" >/dev/null
  "$new" render "$vdb" -o "$tmp/new.png" --stats "$tmp/new.json" "$@" >/dev/null
  best_old=$(python3 -c "print(min(float('$best_old'), $(seconds "$tmp/old.json")))")
  best_new=$(python3 -c "print(min(float('$best_new'), $(seconds "$tmp/new.json")))")
done
cmp=$("$new" compare "$tmp/new.png" "$tmp/old.png" | tr '\n' ' ')
python3 -c "import sys; o, n = float(sys.argv[1]), float(sys.argv[2]); print(f'{sys.argv[3]}: old {o:.4f} s, new {n:.4f} s, speed-up {o / n:.2f}x | {sys.argv[4]}')" \
  "$best_old" "$best_new" "$vdb $*" "$cmp"
