#!/bin/bash
# ident.sh A B OUT: 60 renders (5 volumes × 4 distances × default, Phong, slab order) with both binaries, compared (rmse)
A=$1; B=$2; OUT=$3; cd "$(dirname "$0")/../../.."; : > $OUT
for v in engine:ct-bone checkerbox:grey marschner-lobb:grey tubes:grey bonsai:ct-bone; do f=${v%%:*}; tf=${v##*:}
 for d in 8 3 1 0.35; do for fl in "" "--shading phong" "--compositing slabs"; do
  $A render volumes/$f.vdb --tf $tf --distance $d $fl --tables tables -o /tmp/ia.exr 2>/dev/null
  $B render volumes/$f.vdb --tf $tf --distance $d $fl --tables tables -o /tmp/ib.exr 2>/dev/null
  echo "$f d$d [$fl] $($B compare /tmp/ia.exr /tmp/ib.exr 2>&1 | grep -o 'rmse=[^ ]*')" >> $OUT
 done; done; done
