#!/usr/bin/env bash
# The study modes' table of docs/modes.md: PSNR/SSIM and time of ewa, swan and none (with hybrid
# in both filter orders for comparison) against the reference, for the checker box and the
# Engine at the three standard views (--distance 8, 1, 0.35).
# Usage: scripts/modes.sh [--size N] [--spp N]   (default 400, 16; build first: scripts/build.sh)
# Volumes: volumes/checkerbox.vdb (made when missing) and volumes/engine.vdb (converted from
# ../shared/volumes when missing). References are cached in out/modes/ (delete to re-render).
# Writes out/modes/modes.tsv, and an EXR (measured) and a PNG (to look at) of every render.
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=400 SPP=16
while [[ $# -gt 0 ]]; do
  case $1 in
    --size) SIZE=$2; shift 2 ;;
    --spp) SPP=$2; shift 2 ;;
    *) echo "modes.sh: unknown argument $1" >&2; exit 1 ;;
  esac
done
OUT=out/modes
mkdir -p "$OUT"
BIN=$OUT/vdbsplat  # a copy: rebuilding during the run does not change the binary it measures
cp "${BUILD_DIR:-build}/vdbsplat" "$BIN"
[[ -f volumes/checkerbox.vdb ]] || VDBSPLAT=$BIN volumes/make-generated.sh checkerbox >/dev/null
if [[ ! -f volumes/engine.vdb ]]; then
  "$BIN" convert ../shared/volumes/engine_256x256x128_uint8.raw.gz -o volumes/engine.vdb \
      --dims 256,256,128 --type uint8 --threshold 0.1176
fi

stat() { sed -E "s/.*\"$1\": *([^,}]+).*/\1/" <<<"$(tr -d '\n' < $OUT/stats.json)"; }
printf "volume\tdistance\tmode\tpsnr_db\tssim\tseconds\n" > $OUT/modes.tsv
for entry in checkerbox:grey engine:ct-bone; do
  vol=${entry%%:*} tf=${entry##*:}
  for d in 8 1 0.35; do
    ref=$OUT/${vol}_d${d}_reference.exr
    if [[ ! -f $ref ]]; then
      "$BIN" render volumes/$vol.vdb -o $ref --mode reference --tf $tf --distance $d --spp $SPP \
          --size ${SIZE}x${SIZE} --stats $OUT/${vol}_d${d}_reference.json
    fi
    for mode in hybrid hybrid-prefilter ewa swan none; do
      img=$OUT/${vol}_d${d}_${mode}.exr
      order=postfilter
      [[ $mode == *-prefilter ]] && order=prefilter
      "$BIN" render volumes/$vol.vdb -o $img --mode ${mode%-prefilter} --filter-order $order --tf $tf \
          --distance $d --size ${SIZE}x${SIZE} --stats $OUT/stats.json
      m=$("$BIN" compare $img $ref)
      "$BIN" render volumes/$vol.vdb -o ${img%.exr}.png --mode ${mode%-prefilter} --filter-order $order --tf $tf \
          --distance $d --size ${SIZE}x${SIZE}  # to look at (the metrics use the EXR)
      psnr=$(sed -E 's/.*psnr=([^ ]+) dB.*/\1/' <<<"$m")
      ssim=$(sed -E 's/.*ssim=([^ ]+) .*/\1/' <<<"$m")
      printf "%s\t%s\t%s\t%.2f\t%.4f\t%.3f\n" $vol $d $mode $psnr $ssim "$(stat seconds)" >> $OUT/modes.tsv
      echo "$vol distance $d $mode: $m $(stat seconds) s"
    done
  done
done
