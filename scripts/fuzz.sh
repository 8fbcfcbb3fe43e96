#!/usr/bin/env bash
# Coverage-guided fuzzing (libFuzzer) of every loader and parser, for SECONDS each
# (default 60): every tests/fuzz/fuzz_*.cpp (docs/robustness.md lists them).
# Builds them (only them) in build-asan/, as scripts/sanitize.sh configures it, starts from the seeds in
# tests/fuzz/corpus/<target>/ plus what earlier runs found (build-asan/fuzz/corpus/), and
# prints executions, coverage and corpus size per target. A crash, leak, timeout or OOM
# leaves its input in build-asan/fuzz/findings/<target>/ and makes the script fail.
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
#        scripts/fuzz.sh --ci [TARGET...]
# --ci is what .ci/run does: a fixed seed and a fixed number of runs per target (about 5 s
# each here), from the committed seeds only, so CI explores exactly what a local
# `scripts/fuzz.sh --ci` explored and cannot fail on a finding nobody could reproduce; the
# open-ended campaign (SECONDS) is the developer's tool for finding new inputs.
set -euo pipefail
cd "$(dirname "$0")/.."
CI_MODE=0
if [ "${1:-}" = "--ci" ]; then CI_MODE=1; SECONDS_EACH=0; shift; else SECONDS_EACH=${1:-60}; shift || true; fi
# Runs per target in --ci mode (executions per second differ by 1000x: fuzz_vdb forks a reader).
declare -A CI_RUNS=([fuzz_vdb]=300 [fuzz_camera_path]=30000 [fuzz_raw]=3000 [fuzz_nrrd]=1500 [fuzz_vti]=1500 [fuzz_image]=100 [fuzz_tables]=40000 [fuzz_transfer_function]=50000 [fuzz_study_spec]=50000)
BUILD_DIR=${ASAN_BUILD_DIR:-build-asan}
scripts/setup.sh
TARGETS=("$@")
if [ ${#TARGETS[@]} -eq 0 ]; then
  for f in tests/fuzz/fuzz_*.cpp; do TARGETS+=("$(basename "$f" .cpp)"); done
fi
CC=clang CXX=clang++ cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVDBSPLAT_FUZZ=ON >/dev/null
cmake --build "$BUILD_DIR" -j "$(nproc)" --target "${TARGETS[@]}" >/dev/null
export ASAN_OPTIONS=allocator_may_return_null=1:detect_leaks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:suppressions=$PWD/tests/fuzz/ubsan.supp
export LSAN_OPTIONS=suppressions=$PWD/tests/fuzz/lsan.supp
status=0
printf '%-24s %10s %8s %8s %8s\n' target execs cov ft corpus
for t in "${TARGETS[@]}"; do
  name=${t#fuzz_}
  corpus=$BUILD_DIR/fuzz/corpus/$name findings=$BUILD_DIR/fuzz/findings/$name
  budget=(-max_total_time="$SECONDS_EACH")
  if [ "$CI_MODE" = 1 ]; then
    corpus=$BUILD_DIR/fuzz/ci-corpus/$name
    rm -rf "$corpus"
    budget=(-seed=20261123 -runs="${CI_RUNS[$t]:-1000}")
  fi
  mkdir -p "$corpus" "$findings"
  log=$BUILD_DIR/fuzz/$name.log
  rc=0
  "$BUILD_DIR/$t" "$corpus" "tests/fuzz/corpus/$name" "${budget[@]}" \
    -rss_limit_mb=4096 -malloc_limit_mb=4096 -timeout=20 -print_final_stats=1 \
    -artifact_prefix="$findings/" >"$log" 2>&1 || rc=$?
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo '?')
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo '?')
  printf '%-24s %10s %8s %8s %8s\n' "$t" "$execs" "$cov" "$ft" "$(ls "$corpus" | wc -l)"
  if [ "$rc" -ne 0 ]; then
    echo "fuzz: $t failed (exit $rc); input in $findings/, log $log:" >&2
    grep -m5 -E 'ERROR|SUMMARY|runtime error' "$log" >&2 || tail -5 "$log" >&2
    status=1
  fi
done
exit $status
