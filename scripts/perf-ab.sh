#!/usr/bin/env bash
# Speed of two penumbra binaries side by side, for integrator refactors: callgrind instruction
# counts of one small single-threaded render per scene (deterministic, immune to the machine's
# load), then interleaved wall-clock timings (A B A B ...) with their medians.
#
# Usage: scripts/perf-ab.sh OLD_BIN NEW_BIN [RUNS]   (RUNS: timed runs per binary, default 7)
#   SCENES="cornell|--res 64x64 --spp 4;many-rooms --rooms 3|--res 64x64 --spp 4" overrides the set.
# Needs valgrind for the instruction counts (skipped with a note when missing).
set -euo pipefail
cd "$(dirname "$0")/.."
OLD=${1:?usage: scripts/perf-ab.sh OLD_BIN NEW_BIN [RUNS]}
NEW=${2:?usage: scripts/perf-ab.sh OLD_BIN NEW_BIN [RUNS]}
RUNS=${3:-7}
OUT=${OUT:-target/perf-ab}
mkdir -p "$OUT"
IFS=';' read -r -a SET <<<"${SCENES:-cornell|--res 64x64 --spp 4;many-rooms --rooms 3|--res 64x64 --spp 4}"
TIMED_ARGS=${TIMED_ARGS:---res 256x256 --spp 16}

for entry in "${SET[@]}"; do
  scene=${entry%%|*}
  args=${entry#*|}
  # shellcheck disable=SC2206
  scene_args=($scene)
  # shellcheck disable=SC2206
  small=($args)
  if command -v valgrind >/dev/null; then
    for b in old new; do
      bin=$OLD; [ $b = new ] && bin=$NEW
      valgrind --tool=callgrind --callgrind-out-file="$OUT/cg-$b.out" \
        "$bin" render "${scene_args[@]}" "${small[@]}" --threads 1 --quiet -o "$OUT/cg-$b.pfm" \
        >"$OUT/cg-$b.log" 2>&1
      ir=$(grep -m1 '^summary:' "$OUT/cg-$b.out" | awk '{print $2}')
      eval "ir_$b=$ir"
    done
    # shellcheck disable=SC2154
    awk -v s="$scene" -v a="$args" -v o="$ir_old" -v n="$ir_new" 'BEGIN {
      printf "callgrind %s (%s, 1 thread): old %d Ir, new %d Ir, new/old %.4f\n", s, a, o, n, n / o }'
  else
    echo "callgrind: valgrind not installed, skipped"
  fi
  # shellcheck disable=SC2206
  timed=($TIMED_ARGS)
  : >"$OUT/times-old" ; : >"$OUT/times-new"
  for _ in $(seq "$RUNS"); do
    for b in old new; do
      bin=$OLD; [ $b = new ] && bin=$NEW
      "$bin" render "${scene_args[@]}" "${timed[@]}" --quiet -o "$OUT/t-$b.pfm" 2>&1 \
        | sed -n 's/.* render \([0-9.]*\) s.*/\1/p' >>"$OUT/times-$b"
    done
  done
  med() { sort -g "$1" | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
  mo=$(med "$OUT/times-old"); mn=$(med "$OUT/times-new")
  awk -v s="$scene" -v a="$TIMED_ARGS" -v o="$mo" -v n="$mn" -v r="$RUNS" 'BEGIN {
    printf "time %s (%s, %d interleaved runs each): median old %.3f s, new %.3f s, new/old %.3f\n",
      s, a, r, o, n, n / o }'
done
