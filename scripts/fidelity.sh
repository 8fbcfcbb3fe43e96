#!/usr/bin/env bash
# The fidelity table of docs/fidelity.md: PSNR/SSIM of hybrid, splat and point against the
# reference renderer for the checker box, Marschner-Lobb, the converted Engine and the tubes at
# the three standard views (--distance 8, 1, 0.35), 400x400, with the default filter order
# (postfilter) and with --filter-order prefilter (EWA's order, the default before issue 10). The volumes come from volumes/
# (volumes/README.md): the generated ones are made there when missing, the Engine is
# volumes/engine.vdb from volumes/fetch.sh (its rows are skipped when it is absent).
# Reference images are cached in out/fidelity/ (delete them to re-render).
# Usage: scripts/fidelity.sh [--spp N] [--modes LIST] [--flags "FLAGS"] [--tag NAME]
#   LIST: which of hybrid, splat, point, hybrid-prefilter, splat-prefilter, point-prefilter to render
#   (default all six); FLAGS: more render flags for them (not the references), e.g. --flags
#   "--compositing slabs"; NAME: a tag for their images and the tables (fidelity-NAME.md/.tsv).
# Writes out/fidelity/fidelity.md (a Markdown table) and out/fidelity/fidelity.tsv.
set -euo pipefail
cd "$(dirname "$0")/.."
SPP=16
MODES="hybrid splat point hybrid-prefilter splat-prefilter point-prefilter"
FLAGS=
TAG=
while [[ $# -gt 0 ]]; do
  case $1 in
    --spp) SPP=$2; shift 2 ;;
    --modes) MODES=${2//,/ }; shift 2 ;;
    --flags) FLAGS=$2; shift 2 ;;
    --tag) TAG=$2; shift 2 ;;
    *) echo "usage: scripts/fidelity.sh [--spp N] [--modes LIST] [--flags \"FLAGS\"] [--tag NAME]" >&2; exit 1 ;;
  esac
done
NAME=fidelity${TAG:+-$TAG}
scripts/build.sh >/dev/null
BIN=${BUILD_DIR:-build}/vdbsplat
OUT=out/fidelity
VOLS=volumes
mkdir -p "$OUT"

for vol in checkerbox marschner-lobb tubes; do
  [[ -f $VOLS/$vol.vdb ]] || VDBSPLAT=$BIN volumes/make-generated.sh $vol >/dev/null
done
VOLUMES="checkerbox:grey marschner-lobb:grey"
if [[ -f $VOLS/engine.vdb ]]; then
  VOLUMES="$VOLUMES engine:ct-bone tubes:grey"
else
  echo "fidelity: $VOLS/engine.vdb absent (run volumes/fetch.sh engine), skipping the Engine rows" >&2
  VOLUMES="$VOLUMES tubes:grey"
fi

printf "volume\tdistance\tmode\tpsnr_db\tssim\tsplat_pct\tseconds\n" > $OUT/$NAME.tsv
for entry in $VOLUMES; do
  vol=${entry%%:*} tf=${entry##*:}
  for d in 8 1 0.35; do
    ref=$OUT/${vol}_d${d}_reference.exr
    if [[ ! -f $ref ]]; then
      "$BIN" render $VOLS/$vol.vdb -o $ref --mode reference --tf $tf --distance $d --spp $SPP \
          --stats $OUT/${vol}_d${d}_reference.json
    fi
    for mode in $MODES; do
      img=$OUT/${vol}_d${d}_${mode}${TAG:+-$TAG}.exr
      order=postfilter
      [[ $mode == *-prefilter ]] && order=prefilter
      # shellcheck disable=SC2086  # FLAGS: words
      "$BIN" render $VOLS/$vol.vdb -o $img --mode ${mode%-prefilter} --filter-order $order --tf $tf --distance $d \
          --stats $OUT/stats.json $FLAGS
      m=$("$BIN" compare $img $ref)
      psnr=$(sed -E 's/.*psnr=([^ ]+) dB.*/\1/' <<<"$m")
      ssim=$(sed -E 's/.*ssim=([^ ]+) .*/\1/' <<<"$m")
      pct=$(sed -E 's/.*"splat_fraction": *([^,}]+).*/\1/' <<<"$(tr -d '\n' < $OUT/stats.json)")
      secs=$(sed -E 's/.*"seconds": *([^,}]+).*/\1/' <<<"$(tr -d '\n' < $OUT/stats.json)")
      printf "%s\t%s\t%s\t%.2f\t%.4f\t%.1f\t%.2f\n" $vol $d $mode $psnr $ssim \
          "$(awk "BEGIN{print 100*$pct}")" $secs >> $OUT/$NAME.tsv
      echo "$vol distance $d $mode: $m"
    done
  done
done

# Markdown: one row per volume and view, PSNR (dB) of each mode, % splats of the hybrid, then
# the same modes with --filter-order prefilter.
{
  echo "| volume | view | hybrid | splat | point | hybrid % splats | hybrid, prefilter | splat, prefilter | point, prefilter |"
  echo "|---|---|---|---|---|---|---|---|---|"
  awk -F'\t' 'NR > 1 { key = $1 "|" $2; psnr[key, $3] = $4; if ($3 == "hybrid") pct[key] = $6;
                        if (!(key in seen)) { seen[key] = 1; order[n++] = key } }
              END { for (i = 0; i < n; ++i) { split(order[i], k, "|");
                      printf "| %s | --distance %s | %s | %s | %s | %s | %s | %s | %s |\n", k[1], k[2],
                             psnr[order[i], "hybrid"], psnr[order[i], "splat"], psnr[order[i], "point"], pct[order[i]],
                             psnr[order[i], "hybrid-prefilter"], psnr[order[i], "splat-prefilter"],
                             psnr[order[i], "point-prefilter"] } }' \
      $OUT/$NAME.tsv
} > $OUT/$NAME.md
cat $OUT/$NAME.md
