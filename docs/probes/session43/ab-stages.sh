#!/bin/bash
# Alternated renders of several vdbsplat builds on one view (docs/performance.md, session 43): per
# build the median render `seconds`, its ratio to the first build's, page faults, and the stream
# and projection stages' seconds. From the project root:
#   docs/probes/session43/ab-stages.sh ROUNDS DISTANCE VOLUME:TF SIZE BIN...
#   e.g. docs/probes/session43/ab-stages.sh 15 1 checkerbox:grey 400 /tmp/vds_s42 build/vdbsplat
# EXTRA="--warmup 1" times a second render in the same process (warm); THREADS=1 one thread.
R=$1; d=$2; v=$3; sz=$4; shift 4
for r in $(seq $R); do for b in "$@"; do
  $b render volumes/${v%%:*}.vdb --tf ${v##*:} --distance $d --tables tables --size ${sz}x${sz} -o /tmp/ab.png --threads ${THREADS:-2} --stats /tmp/ab.json $EXTRA >/dev/null 2>&1
  python3 -c "import json;d=json.load(open('/tmp/ab.json'));print('$b',d['seconds'],d['page_faults'],d['stage_seconds']['stream'],d['stage_seconds']['project'])"
done; done | python3 -c "
import sys,statistics as st,collections
c=collections.defaultdict(list)
for l in sys.stdin:
  b,s,f,sv,pv=l.split(); c[b].append((float(s),int(f),float(sv),float(pv)))
base=None
for b,v in c.items():
  m=st.median(x[0] for x in v)
  if base is None: base=m
  print(f'{b:22s} median {m*1e3:7.2f} ms  ratio {m/base:.3f}  faults {st.median(x[1] for x in v):6.0f}  stream {st.median(x[2] for x in v)*1e3:6.2f} ms  project {st.median(x[3] for x in v)*1e3:6.2f} ms')
"
