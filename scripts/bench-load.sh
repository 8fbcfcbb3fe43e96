#!/usr/bin/env bash
# Times loading .vdb files: one plain OpenVDB read (io::File::readGrid) against
# vdbsplat::loadVolume, interleaved, median of RUNS, and prints the ratio (the bar of
# issue 9: loadVolume ≤ 1.25 × plain read). Builds scripts/bench-load.cpp against the
# library in build/ (run scripts/build.sh first); makes the volumes it times under out/.
# Usage: scripts/bench-load.sh [RUNS] [FILE.vdb ...]
#   default files: out/engine.vdb, out/cb.vdb, out/cloud20m.vdb (made when missing)
#   LIB=path/to/libvdbsplat_core.a times another build of the library (e.g. the one before a change).
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-7}; shift || true
BUILD_DIR=${BUILD_DIR:-build}
LIB=${LIB:-$BUILD_DIR/libvdbsplat_core.a}
BIN=${BENCH_BIN:-$BUILD_DIR/bench-load}
mkdir -p out
OBJ=$BUILD_DIR/bench-load.o
if [ ! -f "$OBJ" ] || [ "$OBJ" -ot scripts/bench-load.cpp ]; then
  nice c++ -std=c++20 -O2 -DNDEBUG -DGLM_FORCE_XYZW_ONLY -DGLM_ENABLE_EXPERIMENTAL -Isrc -c scripts/bench-load.cpp -o "$OBJ"
fi
if [ ! -x "$BIN" ] || [ "$BIN" -ot "$LIB" ] || [ "$BIN" -ot "$OBJ" ]; then
  nice c++ "$OBJ" "$LIB" -o "$BIN" -lopenvdb -ltbb -lz $(pkg-config --libs Imath OpenImageIO) -lpthread
fi
if [ $# -eq 0 ]; then
  V="$BUILD_DIR/vdbsplat"
  [ -f out/engine.vdb ] || "$V" convert ../shared/volumes/engine_256x256x128_uint8.raw.gz -o out/engine.vdb \
      --dims 256,256,128 --type uint8 --threshold 0.1176
  [ -f out/cb.vdb ] || "$V" generate checkerbox -o out/cb.vdb
  [ -f out/cloud20m.vdb ] || "$V" generate cloud --active 20000000 -o out/cloud20m.vdb
  set -- out/engine.vdb out/cb.vdb out/cloud20m.vdb
fi
for f in "$@"; do "$BIN" "$f" "$RUNS"; done
