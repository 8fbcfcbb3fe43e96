#!/usr/bin/env bash
# Installs (quietly, only what is missing) the Debian packages vdbsplat builds with.
# Idempotent; needs root (or sudo) only when something is missing.
# Usage: scripts/setup.sh [--test]   (--test: also what only the test suite uses; scripts/test.sh)
set -euo pipefail
PKGS=(build-essential cmake ninja-build pkg-config git
      libopenvdb-dev libboost-iostreams-dev libopenexr-dev libglm-dev libtbb-dev
      libgtest-dev libbenchmark-dev nlohmann-json3-dev zlib1g-dev libhwy-dev
      libpng-dev libpugixml-dev libcli11-dev clang)  # clang: the sanitizer and libFuzzer build (scripts/sanitize.sh, scripts/fuzz.sh)
# Test-only packages: the build never needs them, and chromium (about 100 MB with its libraries)
# would slow every quick start. Without it the study report's end-to-end test skips itself.
TEST_PKGS=(chromium)  # headless check of `vdbsplat study`'s index.html (tests/cli/test_cli_study.cpp)
if [ "${1:-}" = "--test" ]; then
  PKGS+=("${TEST_PKGS[@]}")
elif [ $# -gt 0 ]; then
  echo "usage: scripts/setup.sh [--test]" >&2
  exit 2
fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq >/dev/null
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
