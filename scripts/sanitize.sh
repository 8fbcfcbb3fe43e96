#!/usr/bin/env bash
# Sanitizer job: builds vdbsplat, a subset of the tests and the fuzz targets with clang,
# AddressSanitizer + UndefinedBehaviorSanitizer (+ libFuzzer coverage) into build-asan/,
# and runs those tests there. Which tests and why: docs/robustness.md.
# Usage: scripts/sanitize.sh [--build-only] [extra ctest args]   (ASAN_BUILD_DIR overrides build-asan/)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
BUILD_DIR=${ASAN_BUILD_DIR:-build-asan}
build_only=0
if [ "${1:-}" = "--build-only" ]; then build_only=1; shift; fi
CC=clang CXX=clang++ cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVDBSPLAT_FUZZ=ON >/dev/null
# The library's loaders, parsers and writers: every stage's unit tests except test_render
# (full-size reference renders: many minutes under ASan), test_cli (hundreds of runs of the
# binary; the cases behind them are unit-tested here and fuzzed), test_pointfilter and
# test_composite (the forward renderer's inner loops, no input parsing). CI time: see
# docs/robustness.md.
TESTS=(test_volume test_image test_util test_footprint test_metrics test_camera)
FUZZERS=$(cd tests/fuzz && ls fuzz_*.cpp | sed 's/\.cpp$//')
cmake --build "$BUILD_DIR" -j "$(nproc)" --target vdbsplat "${TESTS[@]}" $FUZZERS
[ "$build_only" = 1 ] && exit 0
# allocator_may_return_null: a huge allocation from a corrupt file is bad_alloc, as in the
# release build (OpenVDB's bloscFromStream asks for gigabytes in the forked reader children).
export ASAN_OPTIONS=allocator_may_return_null=1:detect_leaks=1:abort_on_error=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:suppressions=$PWD/tests/fuzz/ubsan.supp
export LSAN_OPTIONS=suppressions=$PWD/tests/fuzz/lsan.supp
cd "$BUILD_DIR"
# The test binaries left out above are registered as <name>_NOT_BUILT placeholders: skip them.
ctest --output-on-failure -j "$(nproc)" -E '_NOT_BUILT$' "$@"
