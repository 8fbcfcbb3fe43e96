#!/usr/bin/env bash
# The Engine with anisotropic and rotated voxels against the reference (issue 11, docs/kernel.md
# section 10): converted with --spacing 1,1,2.5, and through an NRRD header whose space
# directions are a rotation of (1,1,2.5) voxels with an origin; hybrid against the reference at
# the three standard views; then a rigid rotation check: the rotated grid seen by the camera
# carried along with it gives the anisotropic grid's image.
# Usage: scripts/affine-fidelity.sh [SIZE (default 400)] [SPP (default 16)]   (writes out/affine/)
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${1:-400}
SPP=${2:-16}
BIN=build/vdbsplat
OUT=out/affine
RAW=../shared/volumes/engine_256x256x128_uint8.raw.gz
[[ -f $RAW ]] || RAW=volumes/downloads/engine_256x256x128_uint8.raw
[[ -f $RAW ]] || { echo "affine-fidelity: no Engine raw file (volumes/fetch.sh engine)"; exit 0; }
RAW=$(realpath "$RAW")
mkdir -p $OUT
# R = Rz(30°)·Rx(20°); the NRRD's axes are R·diag(1, 1, 2.5), its origin O.
read -r DIRS < <(python3 -c "
import math
c,s=math.cos(math.radians(20)),math.sin(math.radians(20)); C,S=math.cos(math.radians(30)),math.sin(math.radians(30))
R=[[C,-S*c,S*s],[S,C*c,-C*s],[0,s,c]]
print(' '.join('(%.12f,%.12f,%.12f)'%tuple(R[i][j]*[1,1,2.5][j] for i in range(3)) for j in range(3)))")
ENC=raw; [[ $RAW == *.gz ]] && ENC=gzip
cat > $OUT/engine_rot.nhdr <<NHDR
NRRD0004
type: uint8
dimension: 3
sizes: 256 256 128
space dimension: 3
space directions: $DIRS
space origin: (10,-20,5)
encoding: $ENC
data file: $RAW
NHDR
$BIN convert $RAW -o $OUT/engine_aniso.vdb --dims 256,256,128 --type uint8 --threshold 0.1176 --spacing 1,1,2.5
$BIN convert $OUT/engine_rot.nhdr -o $OUT/engine_rot.vdb --threshold 0.1176
echo "| volume | view | hybrid vs reference (dB) | hybrid s | reference s |" > $OUT/affine.md
echo "|---|---|---|---|---|" >> $OUT/affine.md
for vol in engine_aniso engine_rot; do
  for d in 8 1 0.35; do
    common=(--tf ct-bone --size ${SIZE}x${SIZE} --distance $d)
    ref=$OUT/${vol}_d${d}_ref.exr
    [[ -f $ref ]] || $BIN render $OUT/$vol.vdb -o $ref --mode reference --spp $SPP "${common[@]}" --stats $OUT/${vol}_d${d}_ref.json
    $BIN render $OUT/$vol.vdb -o $OUT/${vol}_d${d}_hybrid.exr "${common[@]}" --stats $OUT/${vol}_d${d}_hybrid.json
    $BIN render $OUT/$vol.vdb -o $OUT/${vol}_d${d}_hybrid.png "${common[@]}"
    psnr=$($BIN compare $OUT/${vol}_d${d}_hybrid.exr $ref | sed 's/.*psnr=\([0-9.inf]*\).*/\1/')
    th=$(python3 -c "import json;print('%.2f'%json.load(open('$OUT/${vol}_d${d}_hybrid.json'))['seconds'])")
    tr=$(python3 -c "import json;print('%.1f'%json.load(open('$OUT/${vol}_d${d}_ref.json'))['seconds'])")
    echo "| $vol | --distance $d | $psnr | $th | $tr |" | tee -a $OUT/affine.md
  done
done
# Rigid rotation: world_rot = R·world_aniso + O. Camera of engine_aniso at its framed view,
# explicit; the same camera carried by R and O for engine_rot.
read -r EA LA UA EB LB UB < <(python3 -c "
import math
c,s=math.cos(math.radians(20)),math.sin(math.radians(20)); C,S=math.cos(math.radians(30)),math.sin(math.radians(30))
R=[[C,-S*c,S*s],[S,C*c,-C*s],[0,s,c]]; O=[10,-20,5]
mul=lambda v:[sum(R[i][k]*v[k] for k in range(3)) for i in range(3)]
centre=[127.5,127.5,158.75]; d=[0.9,-1.3,0.75]; n=math.sqrt(sum(x*x for x in d))
eye=[centre[i]+600*d[i]/n for i in range(3)]; up=[0,0,1]
f=lambda v:','.join('%.9f'%x for x in v)
print(f(eye),f(centre),f(up),f([a+b for a,b in zip(mul(eye),O)]),f([a+b for a,b in zip(mul(centre),O)]),f(mul(up)))")
$BIN render $OUT/engine_aniso.vdb -o $OUT/rigid_a.exr --tf ct-bone --size ${SIZE}x${SIZE} --eye $EA --look-at $LA --up $UA
$BIN render $OUT/engine_rot.vdb -o $OUT/rigid_b.exr --tf ct-bone --size ${SIZE}x${SIZE} --eye $EB --look-at $LB --up $UB
echo "rigid rotation of grid and camera: $($BIN compare $OUT/rigid_b.exr $OUT/rigid_a.exr)" | tee -a $OUT/affine.md
