#!/bin/bash
# A/B two builds of the core's `quick` bench on this noisy 2-core VM (a dev tool, never in CI).
# Runs both binaries at the same time, one per core, then again with the cores swapped, and prints
# the minimum per key: both builds see the same machine, whose speed drifts by tens of percent.
# Absolute times are inflated by the co-runner; only the B/A column means anything.
#   cargo bench -p kinedyn-core --bench quick --no-run   # twice, copying target/release/deps/quick-*
#   benches/ab_core.sh /tmp/quick_old /tmp/quick_new [FILTER]
A=$1; B=$2; shift 2
for k in 1 2; do
  if [ $k = 1 ]; then ca=0; cb=1; else ca=1; cb=0; fi
  taskset -c $ca $A --bench "$@" > /tmp/ab_a$k.txt & taskset -c $cb $B --bench "$@" > /tmp/ab_b$k.txt; wait
done
python3 - <<'PY'
import collections
def load(prefix):
    d=collections.defaultdict(lambda: 1e99)
    for k in (1,2):
        for line in open(f"/tmp/ab_{prefix}{k}.txt"):
            parts=line.split()
            if len(parts)!=2: continue  # the trees' check lines and the flop counts carry more numbers
            key,v=parts; d[key]=min(d[key],float(v))
    return d
a=load('a'); b=load('b')
for key in a:
    print(f"{key:28s} A {a[key]:8.1f}  B {b[key]:8.1f}  B/A {b[key]/a[key]:.3f}")
PY
