#!/usr/bin/env bash
# Writes the generated volumes of the catalogue (volumes/README.md) with the sizes and seeds
# the docs use, through `vdbsplat generate`, and checks each one's active voxel count.
#
# usage: volumes/make-generated.sh [--out DIR] [NAME... | all]
#   NAME       checkerbox, marschner-lobb, sphere, cloud, tubes (no NAME or "all": these five),
#              cloud-20m, cloud-100m (the large grids of docs/performance.md, only when
#              named: 66 MB and 314 MB files)
#   --out DIR  where the .vdb files go (default: volumes/)
# The binary is $VDBSPLAT, else ${BUILD_DIR:-build}/vdbsplat (run scripts/build.sh first).
# Output is the same on every run; each file is written to a temporary file and renamed.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

die() { echo "make-generated: error: $*" >&2; exit 1; }

# --- The catalogue: name, `vdbsplat generate` arguments, active voxels -------------------------
STANDARD=(checkerbox marschner-lobb sphere cloud tubes)
LARGE=(cloud-20m cloud-100m)
declare -A ARGS=(
  [checkerbox]="checkerbox --res 100"
  [marschner-lobb]="marschner-lobb --res 41"
  [sphere]="sphere --res 64"
  [cloud]="cloud --active 1000000 --seed 1"
  [tubes]="tubes --res 128 --count 14 --sheets 2 --radius-min 0.7 --radius-max 2.5 --seed 1"
  [cloud-20m]="cloud --active 20000000 --seed 1"
  [cloud-100m]="cloud --active 100000000 --seed 1"
)
declare -A ACTIVE=(
  [checkerbox]=1000000
  [marschner-lobb]=68921
  [sphere]=130536
  [cloud]=1000002
  [tubes]=34740
  [cloud-20m]=19999990
  [cloud-100m]=99999970
)

usage() {
  sed -n '/^# usage:/,/^# The binary/p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}

OUT=$ROOT/volumes
WANT=()
while (($#)); do
  case $1 in
    --out) (($# >= 2)) || die "--out: missing folder"; OUT=$2; shift 2 ;;
    --out=*) OUT=${1#--out=}; shift ;;
    -h|--help) usage; exit 0 ;;
    -*) die "unknown option '$1' (see volumes/make-generated.sh --help)" ;;
    all) WANT+=("${STANDARD[@]}"); shift ;;
    *) [[ -n ${ARGS[$1]+x} ]] || die "unknown volume '$1' (known: ${STANDARD[*]} ${LARGE[*]}, all)"
       WANT+=("$1"); shift ;;
  esac
done
((${#WANT[@]})) || WANT=("${STANDARD[@]}")

mkdir -p "$OUT" 2>/dev/null || die "--out: $OUT: cannot create the folder"
[[ -w $OUT ]] || die "--out: $OUT: not writable"
VDBSPLAT=${VDBSPLAT:-$ROOT/${BUILD_DIR:-build}/vdbsplat}
[[ -x $VDBSPLAT ]] || die "$VDBSPLAT: no such binary (run scripts/build.sh, or set VDBSPLAT)"

TEMPS=()
cleanup() { ((${#TEMPS[@]} == 0)) || rm -f "${TEMPS[@]}"; }
trap cleanup EXIT
trap 'exit 130' INT TERM

declare -A DONE=()
for n in "${WANT[@]}"; do
  [[ -z ${DONE[$n]+x} ]] || continue
  DONE[$n]=1
  dst=$OUT/$n.vdb
  tmp=$(mktemp "$OUT/.$n.XXXXXX.vdb")
  TEMPS+=("$tmp")
  read -r kind args <<<"${ARGS[$n]}"
  # shellcheck disable=SC2086  # the flags are words
  err=$("$VDBSPLAT" generate "$kind" -o "$tmp" $args 2>&1 >/dev/null) ||
    die "$dst: vdbsplat generate failed: ${err#vdbsplat: error: }"
  active=$("$VDBSPLAT" info "$tmp" 2>/dev/null | sed -n 's/^ *active voxels: *\([0-9]*\).*/\1/p' | head -1) ||
    die "$dst: vdbsplat info cannot read the result"
  [[ $active == "${ACTIVE[$n]}" ]] || die "$dst: $active active voxels, the catalogue says ${ACTIVE[$n]}"
  mv -f -- "$tmp" "$dst"
  echo "make-generated: wrote $dst (${ACTIVE[$n]} active voxels)"
done
