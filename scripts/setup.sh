#!/usr/bin/env bash
# Installs (quietly, only what is missing) the Debian packages vdbsplat builds with.
# Idempotent; needs root (or sudo) only when something is missing.
set -euo pipefail
PKGS=(build-essential cmake ninja-build pkg-config git
      libopenvdb-dev libboost-iostreams-dev libopenexr-dev libglm-dev libtbb-dev
      libgtest-dev libbenchmark-dev nlohmann-json3-dev zlib1g-dev libhwy-dev
      libpng-dev libpugixml-dev clang)  # clang: the sanitizer and libFuzzer build (scripts/sanitize.sh, scripts/fuzz.sh)
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
