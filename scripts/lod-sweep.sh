#!/usr/bin/env bash
# The level-of-detail sweep of docs/performance.md (session 20): PSNR against a `--spp 16`
# reference and the points drawn, hybrid, 400², for each volume at each --distance, with one
# vdbsplat binary (build one per kLodMaxSpreadRatio value in src/volume/stream.h, or pass
# render flags such as "--lod 0" or "--lod 2" to compare rules with one binary).
# References are rendered once into out/lod-sweep/ (delete them to re-render).
# Usage: scripts/lod-sweep.sh BIN TAG [render flags...]
#   e.g. scripts/lod-sweep.sh build/vdbsplat r1.25; scripts/lod-sweep.sh build/vdbsplat off --lod 0
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: $0 BIN TAG [render flags...]" >&2; exit 2; }
bin=$1 tag=$2
shift 2
out=out/lod-sweep
mkdir -p "$out"
for v in engine:ct-bone checkerbox:grey marschner-lobb:grey tubes:grey; do
  vol=${v%%:*} tf=${v##*:}
  if [[ ! -f volumes/$vol.vdb ]]; then echo "lod-sweep: volumes/$vol.vdb absent, skipped" >&2; continue; fi
  for d in 8 6 4 3 2 1.5; do
    ref=$out/${vol}_d${d}_reference.exr
    [[ -f $ref ]] || "$bin" render volumes/$vol.vdb --tf "$tf" --distance "$d" --mode reference --spp 16 -o "$ref" >/dev/null
    img=$out/${vol}_d${d}_$tag.exr
    "$bin" render volumes/$vol.vdb --tf "$tf" --distance "$d" -o "$img" --stats "$out/stats.json" "$@" >/dev/null
    psnr=$("$bin" compare "$img" "$ref" | sed -E 's/psnr=([^ ]+) dB.*/\1/')
    points=$(sed -E 's/.*"points": *([0-9]+).*/\1/' <<<"$(tr -d '\n' < "$out/stats.json")")
    echo "$tag $vol --distance $d: psnr $psnr dB, points $points"
  done
done
