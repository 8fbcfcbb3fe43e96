#!/usr/bin/env bash
# The pictures of docs/fidelity.md and the README: the Engine and the Bonsai in hybrid mode
# and with --show-primitives (splats red, points in their colour; seed Figure 8a) at the three
# standard views, 400x400, into out/pictures/. Reads volumes/engine.vdb and volumes/bonsai.vdb
# (made by volumes/fetch.sh; skips what is absent).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh >/dev/null
BIN=${BUILD_DIR:-build}/vdbsplat
OUT=out/pictures
mkdir -p "$OUT"
VOLS=volumes
declare -A TF=([engine]=ct-bone [bonsai]=ct-bone)
# The Bonsai stands along +y: frame it from the side, slightly above.
declare -A VIEW=([engine]="" [bonsai]="--view-dir 1,0.35,0.6 --up 0,1,0")
# A view where the switch runs through the volume: near voxels splats (red), far ones points.
declare -A MIXED=([engine]=1.2 [bonsai]=0.7)
for vol in engine bonsai; do
  if [[ ! -f $VOLS/$vol.vdb ]]; then
    echo "pictures: $VOLS/$vol.vdb absent (run volumes/fetch.sh $vol), skipping it" >&2
    continue
  fi
  for d in 8 1 0.35; do
    "$BIN" render $VOLS/$vol.vdb -o $OUT/${vol}_d${d}_hybrid.png --tf ${TF[$vol]} ${VIEW[$vol]} --distance $d -v
    "$BIN" render $VOLS/$vol.vdb -o $OUT/${vol}_d${d}_primitives.png --tf ${TF[$vol]} ${VIEW[$vol]} --distance $d --show-primitives
  done
  "$BIN" render $VOLS/$vol.vdb -o $OUT/${vol}_d${MIXED[$vol]}_primitives.png --tf ${TF[$vol]} ${VIEW[$vol]} \
      --distance ${MIXED[$vol]} --show-primitives -v
done
# The README's strip: Engine and Bonsai in hybrid mode, then with --show-primitives where the
# switch runs through them.
if [[ -f $OUT/engine_d1_hybrid.png && -f $OUT/bonsai_d0.7_primitives.png ]] && command -v oiiotool >/dev/null; then
  oiiotool $OUT/engine_d1_hybrid.png $OUT/engine_d1.2_primitives.png $OUT/bonsai_d1_hybrid.png \
      $OUT/bonsai_d0.7_primitives.png --mosaic 4x1 --resize 960x240 --ch R,G,B -o $OUT/strip.png
fi
echo "pictures: wrote $(pwd)/$OUT"
