#!/usr/bin/env bash
# The two extra tables of docs/modes.md, at 200x200 (--spp 16 references cached in out/modes-extra/):
#  1. "wide": EWA's affine approximation against hybrid's exact ellipse where it errs most, close
#     to the eye and far off the axis (--fov 90 --distance 0.3), tubes and Engine, both in the
#     prefilter order (EWA's), against the reference;
#  2. "kernel": hybrid (both orders) and ewa with each --kernel against the reference of the same
#     kernel and, to show why the reference must follow the kernel, against the other one;
#     checker box and Engine at --distance 1 and 0.35.
# Usage: scripts/modes-extra.sh   (build first; volumes as scripts/modes.sh, tubes made when missing)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=out/modes-extra
mkdir -p "$OUT"
BIN=$OUT/vdbsplat
cp "${BUILD_DIR:-build}/vdbsplat" "$BIN"
[[ -f volumes/tubes.vdb ]] || VDBSPLAT=$BIN volumes/make-generated.sh tubes >/dev/null
[[ -f volumes/checkerbox.vdb ]] || VDBSPLAT=$BIN volumes/make-generated.sh checkerbox >/dev/null
[[ -f volumes/engine.vdb ]] || "$BIN" convert ../shared/volumes/engine_256x256x128_uint8.raw.gz -o volumes/engine.vdb \
    --dims 256,256,128 --type uint8 --threshold 0.1176
S=200x200
secs() { sed -E 's/.*"seconds": *([^,}]+).*/\1/' <<<"$(tr -d '\n' < $OUT/stats.json)"; }
psnr() { sed -E 's/.*psnr=([^ ]+) dB.*/\1/' <<<"$("$BIN" compare "$1" "$2")"; }
ref() {  # ref NAME VOL TF ARGS...: the cached reference image
  local name=$1 vol=$2 tf=$3; shift 3
  [[ -f $OUT/$name.exr ]] || "$BIN" render volumes/$vol.vdb -o $OUT/$name.exr --mode reference --tf $tf --size $S "$@"
  echo $OUT/$name.exr
}
printf "table\tvolume\tview\tmode\tkernel\tpsnr_vs_same_kernel\tpsnr_vs_other_kernel\tseconds\n" > $OUT/extra.tsv
for entry in tubes:grey engine:ct-bone; do
  vol=${entry%%:*} tf=${entry##*:}
  view="--fov 90 --distance 0.3"
  r=$(ref ${vol}_wide_reference $vol $tf $view)
  for mode in hybrid ewa; do
    img=$OUT/${vol}_wide_$mode.exr
    "$BIN" render volumes/$vol.vdb -o $img --mode $mode --filter-order prefilter --tf $tf --size $S $view --stats $OUT/stats.json
    p=$(psnr $img $r)
    printf "wide\t%s\tfov90_d0.3\t%s\tgaussian\t%s\t-\t%s\n" $vol $mode $p "$(secs)" >> $OUT/extra.tsv
    echo "wide $vol $mode: $p dB"
  done
done
for entry in checkerbox:grey engine:ct-bone; do
  vol=${entry%%:*} tf=${entry##*:}
  for d in 1 0.35; do
    declare -A R=([gaussian]=$(ref ${vol}_d${d}_reference $vol $tf --distance $d)
                  [gaussian-sharp]=$(ref ${vol}_d${d}_reference_sharp $vol $tf --distance $d --kernel gaussian-sharp))
    for kernel in gaussian gaussian-sharp; do
      other=gaussian; [[ $kernel == gaussian ]] && other=gaussian-sharp
      for mode in hybrid hybrid-prefilter ewa; do
        order=postfilter; [[ $mode == *-prefilter ]] && order=prefilter
        img=$OUT/${vol}_d${d}_${mode}_${kernel}.exr
        "$BIN" render volumes/$vol.vdb -o $img --mode ${mode%-prefilter} --filter-order $order --kernel $kernel \
            --tf $tf --size $S --distance $d --stats $OUT/stats.json
        same=$(psnr $img ${R[$kernel]}) cross=$(psnr $img ${R[$other]})
        printf "kernel\t%s\td%s\t%s\t%s\t%s\t%s\t%s\n" $vol $d $mode $kernel $same $cross "$(secs)" >> $OUT/extra.tsv
        echo "kernel $vol d$d $mode $kernel: $same dB vs its own kernel's reference, $cross dB vs the other's"
      done
    done
  done
done
