#!/usr/bin/env bash
# Before/after render time of two vdbsplat binaries on one view, alternating runs so that machine
# noise hits both alike; prints the minimum and the median `seconds` (render only, from --stats)
# of each, their ratios, and `compare` of the two images (rmse 0: identical).
# Usage: scripts/ab.sh OLD_BIN NEW_BIN RUNS FILE.vdb [render flags...]
#   e.g. scripts/ab.sh /tmp/vdbsplat-old build/vdbsplat 5 out/engine.vdb --tf ct-bone --distance 1
set -euo pipefail
[ $# -ge 4 ] || { echo "usage: $0 OLD_BIN NEW_BIN RUNS FILE.vdb [render flags...]" >&2; exit 2; }
old=$1 new=$2 runs=$3 vdb=$4
shift 4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
seconds() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['seconds'])" "$1"; }
times_old="" times_new=""
for _ in $(seq "$runs"); do
  "$old" render "$vdb" -o "$tmp/old.png" --stats "$tmp/old.json" "$@" >/dev/null
  "$new" render "$vdb" -o "$tmp/new.png" --stats "$tmp/new.json" "$@" >/dev/null
  times_old="$times_old $(seconds "$tmp/old.json")"
  times_new="$times_new $(seconds "$tmp/new.json")"
done
cmp=$("$new" compare "$tmp/new.png" "$tmp/old.png" | tr '\n' ' ')
python3 -c "
import statistics, sys
o = [float(x) for x in sys.argv[1].split()]
n = [float(x) for x in sys.argv[2].split()]
print(f'{sys.argv[3]}: old {min(o):.4f} s, new {min(n):.4f} s, speed-up {min(o) / min(n):.2f}x (min); '
      f'median {statistics.median(o):.4f} -> {statistics.median(n):.4f} s, {statistics.median(o) / statistics.median(n):.2f}x | {sys.argv[4]}')
" "$times_old" "$times_new" "$vdb $*" "$cmp"
