#!/usr/bin/env bash
# The pictures of docs/shading.md and the README: the Engine and the Bonsai (ct-bone, framed
# view, hybrid mode), unshaded and with --shading ct (headlight), plus the Engine with a
# directional light and with gradient opacity. 256x256 into docs/images/shading-*.png.
# Reads volumes/engine.vdb and volumes/bonsai.vdb (volumes/fetch.sh; skips what is absent).
# Usage: scripts/shading-pictures.sh [--size WxH] [--out DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=256x256
OUT=docs/images
while [[ $# -gt 0 ]]; do
  case $1 in
    --size) SIZE=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    *) echo "usage: scripts/shading-pictures.sh [--size WxH] [--out DIR]" >&2; exit 1 ;;
  esac
done
BIN=${BUILD_DIR:-build}/vdbsplat
VOLS=volumes
mkdir -p "$OUT"
# The Bonsai stands along +y: frame it from the side, slightly above (as scripts/pictures.sh).
declare -A VIEW=([engine]="" [bonsai]="--view-dir 1,0.35,0.6 --up 0,1,0")
for vol in engine bonsai; do
  if [[ ! -f $VOLS/$vol.vdb ]]; then
    echo "shading-pictures: $VOLS/$vol.vdb absent (run volumes/fetch.sh $vol), skipping it" >&2
    continue
  fi
  for shading in off ct; do
    "$BIN" render $VOLS/$vol.vdb -o $OUT/shading-${vol}-${shading}.png --tf ct-bone ${VIEW[$vol]} \
        --size $SIZE --shading $shading -v
  done
done
if [[ -f $VOLS/engine.vdb ]]; then
  "$BIN" render $VOLS/engine.vdb -o $OUT/shading-engine-light.png --tf ct-bone --size $SIZE \
      --shading ct --light -1,-0.3,1 -v
  "$BIN" render $VOLS/engine.vdb -o $OUT/shading-engine-gradient-opacity.png --tf ct-bone --size $SIZE \
      --shading ct --gradient-opacity 100 -v
fi
echo "shading-pictures: wrote $(pwd)/$OUT/shading-*.png"
