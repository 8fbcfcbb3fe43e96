#!/usr/bin/env bash
# Quick start, part 1: set up, build, generate the seed paper's 3D Checker Box
# (100x100x100) and render it to out/demo.png at 400x400.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh >/dev/null
BIN=${BUILD_DIR:-build}/vdbsplat
mkdir -p out
"$BIN" generate checkerbox -o out/checkerbox.vdb
"$BIN" render out/checkerbox.vdb -o out/demo.png --size 400x400 "$@"
echo "demo: wrote $(pwd)/out/demo.png"
