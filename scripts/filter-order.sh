#!/usr/bin/env bash
# The two filter orders of the forward modes (--filter-order prefilter | postfilter, issue 10 §1,
# docs/fidelity.md "Thin dense structures") side by side: PSNR of the hybrid against the reference
# on the tubes at 160² and 400², --distance 1 and 0.5, and the render time of each order as the
# median of interleaved repeated renders (one process per render, load included in neither:
# the "seconds" of --stats).
# Usage: scripts/filter-order.sh [--runs N]     (default 5)
# Writes out/filter-order/filter-order.tsv; reference images are cached there.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=5
[[ "${1:-}" == "--runs" ]] && RUNS=$2
BIN=${BUILD_DIR:-build}/vdbsplat
[[ -x $BIN ]] || scripts/build.sh >/dev/null
OUT=out/filter-order
mkdir -p "$OUT"
[[ -f volumes/tubes.vdb ]] || VDBSPLAT=$BIN volumes/make-generated.sh tubes >/dev/null

seconds() { sed -E 's/.*"seconds": *([^,}]+).*/\1/' <<<"$(tr -d '\n' < "$1")"; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

printf "size\tdistance\tprefilter_db\tpostfilter_db\tprefilter_s\tpostfilter_s\tratio\n" > $OUT/filter-order.tsv
for size in 160 400; do
  for d in 1 0.5; do
    common=(volumes/tubes.vdb --tf grey --distance $d --size ${size}x${size})
    ref=$OUT/tubes_${size}_d${d}_reference.exr
    [[ -f $ref ]] || "$BIN" render "${common[@]}" -o $ref --mode reference --spp 16
    declare -A psnr=() times=()
    for run in $(seq "$RUNS"); do
      for order in prefilter postfilter; do
        img=$OUT/tubes_${size}_d${d}_$order.exr
        "$BIN" render "${common[@]}" -o $img --filter-order $order --stats $OUT/stats.json
        times[$order]+="$(seconds $OUT/stats.json) "
      done
    done
    for order in prefilter postfilter; do
      psnr[$order]=$("$BIN" compare $OUT/tubes_${size}_d${d}_$order.exr $ref | sed -E 's/.*psnr=([^ ]+) dB.*/\1/')
      times[$order]=$(tr ' ' '\n' <<<"${times[$order]}" | grep . | median)
    done
    ratio=$(awk "BEGIN { printf \"%.2f\", ${times[postfilter]} / ${times[prefilter]} }")
    printf "%s\t%s\t%s\t%s\t%.3f\t%.3f\t%s\n" $size $d ${psnr[prefilter]} ${psnr[postfilter]} \
        ${times[prefilter]} ${times[postfilter]} $ratio | tee -a $OUT/filter-order.tsv
  done
done
