#!/usr/bin/env bash
# The study of docs/study.md: the checker box, Marschner-Lobb and the thin tubes (grey) in one
# report, the Engine (ct-bone) in a second, every forward mode of the build, the standard views
# and the zoom ladder, at a reduced size for a small shared machine (160x160, reference 16 rays
# per pixel; SIZE and SPP override). Reads volumes/engine.vdb (volumes/fetch.sh engine; skipped
# when absent), generates the others. Writes out/study-generated/ and out/study-engine/, and
# with chromium installed a screenshot of each report beside its index.html.
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
COMMON=(--size "$SIZE" --spp "$SPP" --views standard,ladder "$AGAIN")
"$BIN" study $VOLS/checkerbox.vdb $VOLS/marschner-lobb.vdb $VOLS/tubes.vdb -o out/study-generated --tf grey "${COMMON[@]}"
if [[ -f $VOLS/engine.vdb ]]; then
  "$BIN" study $VOLS/engine.vdb -o out/study-engine --tf ct-bone "${COMMON[@]}"
else
  echo "study: $VOLS/engine.vdb absent (run volumes/fetch.sh engine), skipping the Engine" >&2
fi
if command -v chromium >/dev/null; then
  for d in out/study-generated out/study-engine; do
    [[ -f $d/index.html ]] || continue
    chromium --headless --disable-gpu --no-sandbox --hide-scrollbars --window-size=1400,1900 \
        --screenshot="$PWD/$d/screenshot.png" "file://$PWD/$d/index.html" 2>/dev/null
  done
fi
