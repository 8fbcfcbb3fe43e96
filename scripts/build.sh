#!/usr/bin/env bash
# Configures and builds vdbsplat (Release, Ninja) into build/ after setup.sh.
# Usage: scripts/build.sh [extra cmake args]   (BUILD_DIR overrides build/)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$BUILD_DIR" -j "$(nproc)"
