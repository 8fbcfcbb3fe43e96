#!/usr/bin/env bash
# Quick start, part 2: set up, build and run the whole test suite through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --test  # the build's packages and the test-only ones (chromium)
scripts/build.sh
cd "${BUILD_DIR:-build}"
ctest --output-on-failure -j "$(nproc)" "$@"
