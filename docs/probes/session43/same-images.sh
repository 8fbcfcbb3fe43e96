#!/bin/bash
# The same images from two builds (docs/performance.md, session 43): 72 EXR renders each (checker
# box, Engine, Bonsai; --distance 8, 3, 1, 0.35; default, splat, point, slab compositing, one
# thread, --simd off), compared with `vdbsplat compare`; prints each that differs and fail=0|1.
# From the project root: docs/probes/session43/same-images.sh OLD_BIN NEW_BIN
B=$1; N=$2; fail=0
for v in checkerbox:grey engine:ct-bone bonsai:ct-bone; do for d in 8 3 1 0.35; do for extra in "" "--mode splat" "--mode point" "--compositing slabs" "--threads 1" "--simd off"; do
  f=${v%%:*}; t=${v##*:}
  $B render volumes/$f.vdb --tf $t --distance $d --tables tables -o /tmp/a.exr $extra >/dev/null 2>&1
  $N render volumes/$f.vdb --tf $t --distance $d --tables tables -o /tmp/b.exr $extra >/dev/null 2>&1
  r=$($N compare /tmp/b.exr /tmp/a.exr); if [[ "$r" != *"max_abs=0 "* ]]; then echo "DIFF $f $d $extra $r"; fail=1; fi
done; done; done
echo fail=$fail
