#!/usr/bin/env bash
# Paired render timing of two snee binaries: A and B alternate N times on one scene at one thread;
# prints the median render time of each (snee's own `seconds` from --stats: passes, merge and film,
# not loading) and the median and range of the per-pair ratio B / A.
#   scripts/ab_time.sh BIN_A BIN_B N SCENE SPP [snee render args...]
#   scripts/ab_time.sh /work/snee_old target/release/snee 7 scenes/media_null.xml 256
# Environment variables (e.g. SNEE_BRUTE=off, SNEE_ISA=avx2) apply to both binaries.
set -euo pipefail
a=$1; b=$2; n=$3; scene=$4; spp=$5; shift 5
tmp=$(mktemp -d)
for _ in $(seq "$n"); do
  for bin in "$a" "$b"; do
    "$bin" render "$scene" --spp "$spp" --threads 1 -q -o "$tmp/out.exr" --stats "$tmp/stats.json" "$@"
    python3 -c "import json,sys; print(sys.argv[1], json.load(open(sys.argv[2]))['seconds'])" "$bin" "$tmp/stats.json"
  done
done | python3 -c "
import sys, statistics as st
rows = [l.split() for l in sys.stdin]
n = len(rows) // 2
A = [float(rows[2 * i][1]) for i in range(n)]
B = [float(rows[2 * i + 1][1]) for i in range(n)]
r = [y / x for x, y in zip(A, B)]
print(f'{sys.argv[1]}: A {st.median(A):.4f} s, B {st.median(B):.4f} s, B/A median {st.median(r):.3f} '
      f'(range {min(r):.3f}-{max(r):.3f}, {n} pairs)')
" "$scene"
rm -rf "$tmp"
