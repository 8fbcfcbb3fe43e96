#!/usr/bin/env bash
# The study of docs/study.md: the checker box, Marschner-Lobb, the Engine and the thin tubes
# (grey; the Engine ct-bone) in one report, every forward mode of the build, the standard views
# and the zoom ladder, at a reduced size for a small shared machine (160x160, reference 16 rays
# per pixel; SIZE and SPP override). Reads volumes/engine.vdb (volumes/fetch.sh engine; left
# out when absent), generates the others. Writes out/study/ and, with chromium installed, a
# screenshot of the report's top beside its index.html.
# Usage: scripts/study.sh [--resume]   (continue an interrupted run instead of starting afresh)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh >/dev/null
BIN=${BUILD_DIR:-build}/vdbsplat
SIZE=${SIZE:-160x160} SPP=${SPP:-16}
AGAIN=--force
[[ "${1:-}" == "--resume" ]] && AGAIN=--resume
VOLS=volumes
for vol in checkerbox marschner-lobb tubes; do
  [[ -f $VOLS/$vol.vdb ]] || VDBSPLAT=$BIN volumes/make-generated.sh $vol >/dev/null
done
INPUTS=($VOLS/checkerbox.vdb $VOLS/marschner-lobb.vdb) TFS=grey,grey
if [[ -f $VOLS/engine.vdb ]]; then
  INPUTS+=($VOLS/engine.vdb) TFS=$TFS,ct-bone
else
  echo "study: $VOLS/engine.vdb absent (run volumes/fetch.sh engine), leaving the Engine out" >&2
fi
INPUTS+=($VOLS/tubes.vdb) TFS=$TFS,grey
"$BIN" study "${INPUTS[@]}" -o out/study --tfs $TFS --size "$SIZE" --spp "$SPP" --views standard,ladder "$AGAIN"
if command -v chromium >/dev/null; then
  chromium --headless --disable-gpu --no-sandbox --hide-scrollbars --window-size=1400,1900 \
      --screenshot="$PWD/out/study/screenshot.png" "file://$PWD/out/study/index.html" 2>/dev/null
fi
