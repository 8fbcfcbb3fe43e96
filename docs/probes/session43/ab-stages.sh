#!/bin/bash
# Alternated renders of several vdbsplat builds on one view (docs/performance.md, session 43): per
# build the median render `seconds`, its ratio to the first build's, page faults, and each stage's
# seconds (stream, projection, compositing, rasterization; "other": the rest of `seconds`). From
# the project root:
#   docs/probes/session43/ab-stages.sh ROUNDS DISTANCE VOLUME:TF SIZE BIN...
#   e.g. docs/probes/session43/ab-stages.sh 15 1 checkerbox:grey 400 /tmp/vds_s42 build/vdbsplat
# EXTRA="--warmup 1" times a second render in the same process (warm); THREADS=1 one thread.
# One-shot against warm in one run (session 45): a BIN that is a wrapper adding --warmup, e.g.
#   printf '#!/bin/sh\nexec %s/build/vdbsplat "$@" --warmup 2\n' "$PWD" > /tmp/vds-warm && chmod +x /tmp/vds-warm
R=$1; d=$2; v=$3; sz=$4; shift 4
for r in $(seq $R); do for b in "$@"; do
  $b render volumes/${v%%:*}.vdb --tf ${v##*:} --distance $d --tables tables --size ${sz}x${sz} -o /tmp/ab.png --threads ${THREADS:-2} --stats /tmp/ab.json $EXTRA >/dev/null 2>&1
  python3 -c "import json;d=json.load(open('/tmp/ab.json'));st=d['stage_seconds'];print('$b',d['seconds'],d['page_faults'],*(st[k] for k in ('stream','project','composite','rasterize')))"
done; done | python3 -c "
import sys,statistics as st,collections
c=collections.defaultdict(list)
for l in sys.stdin:
  b,s,f,*x=l.split(); c[b].append((float(s),int(f),*map(float,x)))
base=None
for b,v in c.items():
  m=st.median(x[0] for x in v)
  if base is None: base=m
  s=[st.median(x[k] for x in v)*1e3 for k in (2,3,4,5)]
  print(f'{b:22s} median {m*1e3:7.2f} ms  ratio {m/base:.3f}  faults {st.median(x[1] for x in v):6.0f}  stream {s[0]:6.2f}  project {s[1]:6.2f}  composite {s[2]:6.2f}  rasterize {s[3]:6.2f}  other {m*1e3-sum(s):6.2f} ms')
"
