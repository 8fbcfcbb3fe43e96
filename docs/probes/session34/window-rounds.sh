#!/bin/bash
# Session 34: one-shot renders at three window caps (maxWindowVoxels 2^17, the default; 2^16; 2^15,
# with minWindowVoxels a quarter of each), alternated N times; prints each cap's `seconds` and
# `page_faults`. Needs a build with window-env.patch (VDS_MAXW, VDS_MINW), in VDS_BIN.
# Usage: VDS_BIN=/tmp/vds_envw docs/probes/session34/window-rounds.sh 9 checkerbox grey 1 400x400
set -euo pipefail
N=$1 vol=$2 tf=$3 d=$4 sz=$5
bin=${VDS_BIN:?build with window-env.patch}
for _ in $(seq "$N"); do
  for cfg in "131072 32768" "65536 16384" "32768 8192"; do
    set -- $cfg
    VDS_MAXW=$1 VDS_MINW=$2 "$bin" render "volumes/$vol.vdb" --tf "$tf" --distance "$d" --size "$sz" \
      -o /tmp/w.png --stats /tmp/w.json >/dev/null
    echo "$1 $(grep -oE '"(seconds|page_faults)": [0-9.e-]+' /tmp/w.json | awk '{print $2}' | tr '\n' ' ')"
  done
done | awk '{s[$1]=s[$1]" "$3; f[$1]=f[$1]" "$2} END {for (k in s) print k, "seconds:", s[k], "| faults:", f[k]}'
