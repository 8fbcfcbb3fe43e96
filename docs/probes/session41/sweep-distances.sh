#!/bin/bash
# usage: sweep-distances.sh SIZE "DISTS" — base vs cap2 1.5 PSNR at extra distances (refs cached in out/lod-sweep/extra)
s=$1; dists=$2; cd /work/main; mkdir -p out/lod-sweep/extra
for v in engine:ct-bone checkerbox:grey marschner-lobb:grey tubes:grey bonsai:ct-bone; do vol=${v%%:*}; tf=${v##*:}
 for d in $dists; do
  ref=out/lod-sweep/extra/${vol}_${s}_d${d}_reference.exr
  [ -f $ref ] || /tmp/vds_base render volumes/$vol.vdb --tf $tf --distance $d --size ${s}x$s --mode reference --spp 16 -o $ref >/dev/null
  line="$vol $s d$d"
  for c in 0 1.5; do
   VDS_CAP2=$c /tmp/vds_cap2 render volumes/$vol.vdb --tf $tf --distance $d --size ${s}x$s -o /tmp/sd.exr --stats /tmp/sd.json --tables tables >/dev/null
   p=$(/tmp/vds_base compare /tmp/sd.exr $ref | sed -E 's/psnr=([^ ]+) dB.*/\1/')
   n=$(python3 -c "import json;print(json.load(open('/tmp/sd.json'))['points'])")
   line="$line | cap2=$c $p ($n)"
  done; echo "$line"
 done; done
