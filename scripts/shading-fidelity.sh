#!/usr/bin/env bash
# The shading rows of docs/shading.md: PSNR of hybrid against the reference, unshaded and with
# --shading ct (the reference equally shaded), for the checker box (grey) and the Engine
# (ct-bone) at the three standard views (--distance 8, 1, 0.35). Same method as
# scripts/fidelity.sh; smaller images by default. (The cost of shading: vdbsplat bench
# --shading ct against --shading off, docs/shading.md.)
# Reference images are cached in out/shading/ (delete them to re-render).
# Usage: scripts/shading-fidelity.sh [--size WxH] [--spp N] [--shading MODE] [--volumes LIST]
#                                    [--flags "FLAGS"] [--tag NAME]
#   defaults: 256x256, 16 rays, --shading ct, checkerbox:grey and (if present) engine:ct-bone;
#   LIST: comma-separated NAME:TF for volumes/NAME.vdb, e.g. the fidelity table's four at 400²:
#   scripts/shading-fidelity.sh --size 400x400 --shading phong \
#     --volumes checkerbox:grey,marschner-lobb:grey,engine:ct-bone,tubes:grey
#   FLAGS: more render flags for the hybrid renders only (the references do not change), e.g.
#   --flags "--compositing slabs" (docs/compositing.md); NAME: a tag for the hybrid images and the
#   table, so that runs with other flags keep theirs (out/shading/shading-NAME.tsv).
# Writes out/shading/shading.tsv (or shading-NAME.tsv) and prints one line per row.
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=256x256
SPP=16
SHADED=ct
LIST=
FLAGS=
TAG=
while [[ $# -gt 0 ]]; do
  case $1 in
    --size) SIZE=$2; shift 2 ;;
    --spp) SPP=$2; shift 2 ;;
    --shading) SHADED=$2; shift 2 ;;
    --volumes) LIST=$2; shift 2 ;;
    --flags) FLAGS=$2; shift 2 ;;
    --tag) TAG=$2; shift 2 ;;
    *) echo "usage: scripts/shading-fidelity.sh [--size WxH] [--spp N] [--shading MODE] [--volumes LIST] [--flags \"FLAGS\"] [--tag NAME]" >&2; exit 1 ;;
  esac
done
TSV=shading${TAG:+-$TAG}.tsv
BIN=${BUILD_DIR:-build}/vdbsplat
OUT=out/shading
VOLS=volumes
mkdir -p "$OUT"
[[ -f $VOLS/checkerbox.vdb ]] || VDBSPLAT=$BIN volumes/make-generated.sh checkerbox >/dev/null
VOLUMES="checkerbox:grey"
if [[ -n $LIST ]]; then
  VOLUMES=""
  for entry in ${LIST//,/ }; do
    if [[ -f $VOLS/${entry%%:*}.vdb ]]; then VOLUMES="$VOLUMES $entry"
    else echo "shading-fidelity: $VOLS/${entry%%:*}.vdb absent (volumes/fetch.sh or volumes/make-generated.sh), skipping it" >&2; fi
  done
elif [[ -f $VOLS/engine.vdb ]]; then
  VOLUMES="$VOLUMES engine:ct-bone"
else
  echo "shading-fidelity: $VOLS/engine.vdb absent (run volumes/fetch.sh engine), skipping the Engine rows" >&2
fi

json() { sed -E "s/.*\"$2\": *([^,}]+).*/\1/" <<<"$(tr -d '\n' < "$1")"; }

printf "volume\tdistance\tshading\tpsnr_db\tssim\trender_s\n" > $OUT/$TSV
for entry in $VOLUMES; do
  vol=${entry%%:*} tf=${entry##*:}
  for d in 8 1 0.35; do
    for shading in off $SHADED; do
      tag=${vol}_d${d}_${shading}_${SIZE}
      ref=$OUT/${tag}_reference.exr
      [[ -f $ref ]] || "$BIN" render $VOLS/$vol.vdb -o $ref --mode reference --tf $tf --distance $d \
          --size $SIZE --spp $SPP --shading $shading
      img=$OUT/${tag}_hybrid${TAG:+-$TAG}.exr
      # shellcheck disable=SC2086  # FLAGS: words
      "$BIN" render $VOLS/$vol.vdb -o $img --tf $tf --distance $d --size $SIZE --shading $shading \
          --stats $OUT/stats.json $FLAGS
      m=$("$BIN" compare $img $ref)
      psnr=$(sed -E 's/.*psnr=([^ ]+) dB.*/\1/' <<<"$m")
      ssim=$(sed -E 's/.*ssim=([^ ]+) .*/\1/' <<<"$m")
      secs=$(json $OUT/stats.json seconds)
      printf "%s\t%s\t%s\t%.2f\t%.4f\t%.3f\n" $vol $d $shading $psnr $ssim $secs >> $OUT/$TSV
      echo "$vol distance $d shading $shading: $m (hybrid $secs s)"
    done
  done
done
