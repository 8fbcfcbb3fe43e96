#!/usr/bin/env bash
# Times loading .vdb files: one plain OpenVDB read (io::File open + readGrid + close)
# against vdbsplat::loadVolume, each call in a fresh process as `vdbsplat render` and `info`
# load (process start-up not timed), RUNS of each interleaved ABBA, and prints the medians
# and their ratio (issue 9's bar: loadVolume ≤ 1.25 × plain read). With LOOP=1 it also times
# both repeatedly inside one process (a long-lived caller whose heap holds freed grids).
# Builds scripts/bench-load.cpp against the library in build/ (run scripts/build.sh first)
# and makes the default volumes under out/ when they are missing.
# Usage: scripts/bench-load.sh [RUNS] [FILE.vdb ...]
#   default files: out/engine.vdb, out/cb.vdb, out/cloud20m.vdb
#   LIB=path/libvdbsplat_core.a BENCH_BIN=path/bench-load: time another build of the library.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-9}; shift || true
BUILD_DIR=${BUILD_DIR:-build}
LIB=${LIB:-$BUILD_DIR/libvdbsplat_core.a}
BIN=${BENCH_BIN:-$BUILD_DIR/bench-load}
OBJ=$BUILD_DIR/bench-load.o
mkdir -p out
if [ ! -f "$OBJ" ] || [ "$OBJ" -ot scripts/bench-load.cpp ]; then
  nice c++ -std=c++20 -O2 -DNDEBUG -DGLM_FORCE_XYZW_ONLY -DGLM_ENABLE_EXPERIMENTAL -Isrc -c scripts/bench-load.cpp -o "$OBJ"
fi
if [ ! -x "$BIN" ] || [ "$BIN" -ot "$LIB" ] || [ "$BIN" -ot "$OBJ" ]; then
  nice c++ "$OBJ" "$LIB" -o "$BIN" -lopenvdb -ltbb -lz $(pkg-config --libs Imath OpenEXR libpng) -lhwy -lpugixml -lblosc -lpthread
fi
if [ $# -eq 0 ]; then
  V="$BUILD_DIR/vdbsplat"
  [ -f out/engine.vdb ] || "$V" convert ../shared/volumes/engine_256x256x128_uint8.raw.gz -o out/engine.vdb \
      --dims 256,256,128 --type uint8 --threshold 0.1176
  [ -f out/cb.vdb ] || "$V" generate checkerbox -o out/cb.vdb
  [ -f out/cloud20m.vdb ] || "$V" generate cloud --active 20000000 -o out/cloud20m.vdb
  set -- out/engine.vdb out/cb.vdb out/cloud20m.vdb
fi
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
for f in "$@"; do
  "$BIN" "$f" plain >/dev/null  # page cache
  plain=(); load=()
  for ((i = 0; i < RUNS; i++)); do
    if ((i % 2 == 0)); then
      plain+=("$("$BIN" "$f" plain)"); load+=("$("$BIN" "$f" load)")
    else
      load+=("$("$BIN" "$f" load)"); plain+=("$("$BIN" "$f" plain)")
    fi
  done
  mp=$(printf '%s\n' "${plain[@]}" | median); ml=$(printf '%s\n' "${load[@]}" | median)
  awk -v f="$f" -v n="$RUNS" -v p="$mp" -v l="$ml" \
    'BEGIN {printf "%s: %d fresh processes each: plain read median %.4f s, loadVolume median %.4f s, ratio %.3f\n", f, n, p, l, l / p}'
  if [ "${LOOP:-0}" = 1 ]; then "$BIN" "$f" loop "$RUNS"; fi
done
