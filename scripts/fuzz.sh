#!/usr/bin/env bash
# A fuzz campaign on one target (pbrt, obj, gltf, ply, image) with cargo-fuzz on nightly:
#   scripts/fuzz.sh TARGET [SECONDS]        (default 3600 s; one job, one core)
#   scripts/fuzz.sh all [SECONDS]           (each of the five in turn, SECONDS each)
#   RUNS=10000000 scripts/fuzz.sh TARGET S  (stops at RUNS executions or S seconds, the first)
# On a shared machine run it as `nice -n 19 scripts/fuzz.sh ...`.
# The corpus grows in fuzz/corpus/TARGET/ (local, not committed: it derives from the
# third-party scenes), seeded from fuzz/seeds/TARGET/, fuzz/regressions/TARGET/ and
# ../shared/scenes/. Crashes, timeouts and OOMs land in fuzz/artifacts/TARGET/; minimise one
# with `cargo +nightly fuzz tmin TARGET FILE`, save it in fuzz/regressions/TARGET/ and fix it:
# tests/fuzz_replay.rs replays them all on stable. The last line libFuzzer prints, "Done N runs
# in S second(s)", is the execution count to report.
set -euo pipefail
target=${1:?usage: scripts/fuzz.sh pbrt|obj|gltf|ply|image|all [SECONDS]}
secs=${2:-3600}
root=$(cd "$(dirname "$0")/.." && pwd)
if [ "$target" = all ]; then
  for t in pbrt obj gltf ply image; do
    "$0" "$t" "$secs"
  done
  exit 0
fi
shared="$root/../shared/scenes"
corpus="$root/fuzz/corpus/$target"
mkdir -p "$corpus"
if [ -d "$shared" ]; then
  case $target in
    pbrt) pattern='*.pbrt' ;;
    obj) pattern='*.obj' ;;
    gltf) pattern='*.gl[tb]*' ;;
    ply) pattern='*.ply' ;;
    *) pattern='' ;;
  esac
  if [ -n "$pattern" ]; then
    find "$shared" -name "$pattern" -size -64k -exec cp -n {} "$corpus/" \;
  fi
else
  echo "note: $shared is missing: seeding from fuzz/seeds only" >&2
fi
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz
cd "$root/fuzz"
exec cargo +nightly fuzz run --sanitizer none -O "$target" "$corpus" \
  "seeds/$target" "regressions/$target" -- \
  -max_total_time="$secs" -runs="${RUNS:--1}" -jobs=1 -workers=1 -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
  -print_final_stats=1
