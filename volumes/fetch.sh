#!/usr/bin/env bash
# Fetches the classic volumes of the catalogue (volumes/README.md), checks each file's
# sha256 before anything reads it, and converts it to a .vdb with the catalogue's settings.
#
# usage: volumes/fetch.sh [--from DIR] [--out DIR] NAME... | all
#   NAME       engine, bonsai, smoke; "all" is every one of them
#   --from DIR take local copies from DIR (FILE or FILE.gz, e.g. ../shared/volumes)
#              instead of downloading them
#   --out DIR  where the .vdb files go (default: volumes/); verified raw files are kept in
#              DIR/downloads/
# The binary is $VDBSPLAT, else ${BUILD_DIR:-build}/vdbsplat (run scripts/build.sh first).
#
# Every requested file is obtained and checked first; only when all of them match is anything
# converted. A mismatch, a missing file or a failed download prints one line
# "fetch: error: ..." naming the file and exits 1, leaving no output behind. Outputs are
# written to a temporary file beside the target and renamed into place.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

die() { echo "fetch: error: $*" >&2; exit 1; }

# --- The catalogue: name, file, sha256 of the uncompressed file, sources, conversion ----------
# Sources are tried in order. A source ending in .gz is decompressed after download.
NAMES=(engine bonsai smoke)
declare -A FILE=(
  [engine]=engine_256x256x128_uint8.raw
  [bonsai]=bonsai_256x256x256_uint8.raw
  [smoke]=smoke.vdb
)
declare -A SHA256=(
  [engine]=15cf29cdde69cd6c8b5ab9eeef4d1bb21f276056da4111cb5069ebfbe5b6ff90
  [bonsai]=288d2818cffb50d2e2c9e3b5b0a2520d09b0f5051bb63cca315f3fc7a894af80
  [smoke]=cfc65c633b483471efb741b86d83f71fe343115d5d089ae6dd1fe6b149da38f6
)
declare -A URLS=(
  [engine]="https://klacansky.com/open-scivis-datasets/engine/engine_256x256x128_uint8.raw
            https://raw.githubusercontent.com/mroehlig/basic_web_volume_visualization/136a32b1c5d00fef302f1295645175726fc36437/data/engine_256x256x128_uint8.raw.gz"
  [bonsai]="https://klacansky.com/open-scivis-datasets/bonsai/bonsai_256x256x256_uint8.raw"
  [smoke]="https://raw.githubusercontent.com/daichi-ishida/VSCode-CMakeTemplate/7866843deea79a2e1b1ebeb46492cd029e1871e5/smoke.vdb"
)
# `vdbsplat convert` flags; empty: the file is a .vdb already and is copied as it is.
declare -A CONVERT=(
  [engine]="--dims 256,256,128 --type uint8 --threshold 0.1176"
  [bonsai]="--dims 256,256,256 --type uint8 --threshold 0.1176"
  [smoke]=""
)
# Active voxels of the result (the catalogue's column); checked after each conversion.
declare -A ACTIVE=([engine]=1328027 [bonsai]=1955550 [smoke]=524288)

usage() {
  sed -n '/^# usage:/,/^# The binary/p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}

# --- Arguments ----------------------------------------------------------------------------------
FROM="" OUT=$ROOT/volumes
REQUESTED=()
while (($#)); do
  case $1 in
    --from) (($# >= 2)) || die "--from: missing folder"; FROM=$2; shift 2 ;;
    --from=*) FROM=${1#--from=}; shift ;;
    --out) (($# >= 2)) || die "--out: missing folder"; OUT=$2; shift 2 ;;
    --out=*) OUT=${1#--out=}; shift ;;
    -h|--help) usage; exit 0 ;;
    -*) die "unknown option '$1' (see volumes/fetch.sh --help)" ;;
    all) REQUESTED+=("${NAMES[@]}"); shift ;;
    *) [[ -n ${FILE[$1]+x} ]] || die "unknown volume '$1' (known: ${NAMES[*]}, all)"
       REQUESTED+=("$1"); shift ;;
  esac
done
if ((${#REQUESTED[@]} == 0)); then usage >&2; exit 2; fi
# Each name once, in catalogue order.
WANT=()
for n in "${NAMES[@]}"; do
  for r in "${REQUESTED[@]}"; do [[ $r == "$n" ]] && { WANT+=("$n"); break; }; done
done

[[ -z $FROM || -d $FROM ]] || die "--from: $FROM: no such folder"
mkdir -p "$OUT/downloads" 2>/dev/null || die "--out: $OUT: cannot create the folder"
[[ -w $OUT ]] || die "--out: $OUT: not writable"
VDBSPLAT=${VDBSPLAT:-$ROOT/${BUILD_DIR:-build}/vdbsplat}
for n in "${WANT[@]}"; do
  if [[ -n ${CONVERT[$n]} && ! -x $VDBSPLAT ]]; then
    die "$VDBSPLAT: no such binary (run scripts/build.sh, or set VDBSPLAT)"
  fi
done

# Temporaries are removed however the script ends.
TEMPS=()
cleanup() { ((${#TEMPS[@]} == 0)) || rm -f "${TEMPS[@]}"; }
trap cleanup EXIT
trap 'exit 130' INT TERM

sha256of() { sha256sum "$1" | cut -d' ' -f1; }
# mktemp makes 0600 files; what is renamed into place gets the umask's usual mode.
MODE=$(printf '%03o' $((0666 & ~0$(umask))))

# Copies SRC (plain, or gzip-compressed when it ends in .gz) to DST; 1 on a damaged .gz.
unpack() {
  local src=$1 dst=$2
  if [[ $src == *.gz ]]; then gzip -dc -- "$src" > "$dst" 2>/dev/null
  else cp -- "$src" "$dst"; fi
}

# Obtains the file of volume $1 into $OUT/downloads/ and checks its sha256. A file already
# there is re-checked and kept when it matches. Exits with one error line on failure.
obtain() {
  local n=$1 file=${FILE[$1]} want=${SHA256[$1]}
  local dst=$OUT/downloads/$file part got src url
  part=$(mktemp "$OUT/downloads/.$file.XXXXXX.part")
  TEMPS+=("$part")
  if [[ -n $FROM ]]; then
    if [[ -f $FROM/$file ]]; then src=$FROM/$file
    elif [[ -f $FROM/$file.gz ]]; then src=$FROM/$file.gz
    else die "$FROM/$file: no such file (nor $file.gz)"; fi
    unpack "$src" "$part" || die "$src: not a readable gzip file"
    got=$(sha256of "$part")
    [[ $got == "$want" ]] || die "$src: sha256 mismatch for $file (expected $want, got $got); refusing it"
  else
    if [[ -f $dst && $(sha256of "$dst") == "$want" ]]; then
      echo "fetch: $file: already here, checksum ok"
      rm -f "$part"
      return
    fi
    local tried=() raw
    for url in ${URLS[$n]}; do
      raw=$part.download
      TEMPS+=("$raw")
      echo "fetch: downloading $url"
      if command -v curl >/dev/null; then
        curl -fsSL --retry 2 --connect-timeout 20 -o "$raw" "$url" 2>/dev/null || { tried+=("$url: download failed"); continue; }
      elif command -v wget >/dev/null; then
        wget -q -T 20 -O "$raw" "$url" || { tried+=("$url: download failed"); continue; }
      else
        die "$file: neither curl nor wget is installed"
      fi
      if [[ $url == *.gz ]]; then
        gzip -dc -- "$raw" > "$part" 2>/dev/null || { tried+=("$url: not a readable gzip file"); continue; }
      else
        mv -f -- "$raw" "$part"
      fi
      got=$(sha256of "$part")
      [[ $got == "$want" ]] && break
      tried+=("$url: sha256 mismatch (expected $want, got $got)")
      got=""
    done
    if [[ ${got:-} != "$want" ]]; then
      local why; why=$(printf '%s; ' "${tried[@]}")
      die "$file: no source gave the right file (${why%; }); refusing it"
    fi
  fi
  chmod "$MODE" "$part"
  mv -f -- "$part" "$dst"
  echo "fetch: $file: sha256 ok"
}

# Active voxel count of the first grid of a .vdb, from `vdbsplat info`.
activeOf() {
  "$VDBSPLAT" info "$1" | sed -n 's/^ *active voxels: *\([0-9]*\).*/\1/p' | head -1
}

# Converts (or copies) the checked file of volume $1 into $OUT/$1.vdb and checks its count.
convert_one() {
  local n=$1 src=$OUT/downloads/${FILE[$1]} dst=$OUT/$1.vdb tmp active err
  tmp=$(mktemp "$OUT/.$n.XXXXXX.vdb")
  TEMPS+=("$tmp")
  # Re-check: the file was verified in this run, but nothing reads it unverified.
  [[ $(sha256of "$src") == "${SHA256[$n]}" ]] || die "$src: changed since it was checked; refusing it"
  if [[ -n ${CONVERT[$n]} ]]; then
    # shellcheck disable=SC2086  # the flags are words
    err=$("$VDBSPLAT" convert "$src" -o "$tmp" ${CONVERT[$n]} 2>&1 >/dev/null) ||
      die "$src: vdbsplat convert failed: ${err#vdbsplat: error: }"
  else
    cp -- "$src" "$tmp"
  fi
  if [[ -x $VDBSPLAT ]]; then
    active=$(activeOf "$tmp" 2>/dev/null) || die "$dst: vdbsplat info cannot read the result"
    [[ $active == "${ACTIVE[$n]}" ]] || die "$dst: $active active voxels, the catalogue says ${ACTIVE[$n]}"
  fi
  chmod "$MODE" "$tmp"
  mv -f -- "$tmp" "$dst"
  echo "fetch: wrote $dst (${ACTIVE[$n]} active voxels)"
}

for n in "${WANT[@]}"; do obtain "$n"; done
for n in "${WANT[@]}"; do convert_one "$n"; done
