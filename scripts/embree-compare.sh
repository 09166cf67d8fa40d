#!/usr/bin/env bash
# penumbra's ray core against system Embree 3 (Debian: apt-get install -y libembree-dev) on the
# same triangles and the same incoherent rays, single-threaded, side by side:
#   scripts/embree-compare.sh [SCENES (default "dense cornell")] [ROUNDS (3)] [RAYS (1000000)]
# Each round runs examples/embree_compare (penumbra; it also writes triangles, rays and its hits)
# then scripts/embree_compare.c on each ray set; the table shows per-query medians over rounds
# (each itself a median of 3 repetitions) and penumbra / Embree. Embree's answers are compared
# ray by ray with penumbra's closest hits (ties: another triangle at the same t).
set -euo pipefail
cd "$(dirname "$0")/.."
scenes=${1:-dense cornell}
rounds=${2:-3}
rays=${3:-1000000}
out=target/embree
mkdir -p "$out"
cargo build --release --example embree_compare
cc -O3 -march=native -Wall -o "$out/embree_compare" scripts/embree_compare.c -lembree3 -lm
log="$out/log.txt"
: >"$log"
for r in $(seq "$rounds"); do
  for s in $scenes; do
    ./target/release/examples/embree_compare "$s" "$out" "$rays" 3 | tee -a "$log"
    for set in random bounce; do
      "$out/embree_compare" "$out" "$s" "$set" 3 | tee -a "$log"
    done
  done
done
python3 - "$log" <<'PY'
import sys, statistics as st
rows = {}
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) == 6 and f[0] in ("penumbra", "embree"):
        rows.setdefault((f[1], f[2], f[3]), {}).setdefault(f[0], []).append((float(f[4]), int(f[5])))
print("| scene | rays | query | penumbra Mrays/s | Embree Mrays/s | ratio | hits penumbra / Embree |")
print("|---|---|---|---|---|---|---|")
for (scene, rs, q), v in rows.items():
    p, e = st.median(x for x, _ in v["penumbra"]), st.median(x for x, _ in v["embree"])
    print(f"| {scene} | {rs} | {q} | {p:.2f} | {e:.2f} | {p / e:.2f} | {v['penumbra'][0][1]} / {v['embree'][0][1]} |")
PY
grep differences "$log" | sort -u
