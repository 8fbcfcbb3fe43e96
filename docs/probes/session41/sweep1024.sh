#!/bin/bash
# usage: sweep1024.sh TAG BIN [env...]  — PSNR at 1024² against out/lod-sweep refs
tag=$1; bin=$2; shift 2
cd /work/main
for r in out/lod-sweep/*_1024_d*_reference.exr; do
  b=$(basename $r _reference.exr); vol=${b%%_1024_*}; d=${b##*_d}
  case $vol in engine|bonsai) tf=ct-bone;; *) tf=grey;; esac
  env "$@" $bin render volumes/$vol.vdb --tf $tf --distance $d --size 1024x1024 -o /tmp/sw_$tag.exr --stats /tmp/sw_$tag.json --tables tables >/dev/null
  p=$($bin compare /tmp/sw_$tag.exr $r | sed -E 's/psnr=([^ ]+) dB.*/\1/')
  n=$(python3 -c "import json;print(json.load(open('/tmp/sw_$tag.json'))['points'])")
  echo "$tag $vol --distance $d: psnr $p dB, points $n"
done
