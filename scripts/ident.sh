#!/usr/bin/env bash
# Bit-identity of two penumbra binaries over a grid of renders: for integrator refactors that
# must not change a bit of the image. Every scene × strategy × selector × pattern × shadow-ray
# count below is rendered by both binaries at a small resolution to PFM (raw floats), and the
# files are compared byte for byte; a pair that differs is reported with `penumbra compare`.
#
# Usage: scripts/ident.sh OLD_BIN NEW_BIN [OUT_DIR]
#   QUICK=1  fewer combinations (one selector per scene, patterns stratified + sobol, M = 1 | 2
#            only on cornell) for a check while developing.
# Exit status 0 when every pair is identical. Needs ../shared/ for the cornell scenes.
set -euo pipefail
cd "$(dirname "$0")/.."
OLD=${1:?usage: scripts/ident.sh OLD_BIN NEW_BIN [OUT_DIR]}
NEW=${2:?usage: scripts/ident.sh OLD_BIN NEW_BIN [OUT_DIR]}
OUT=${3:-target/ident}
QUICK=${QUICK:-0}
mkdir -p "$OUT/old" "$OUT/new"
if [ ! -d ../shared/scenes ]; then
  echo "ident.sh: ../shared/scenes is missing (the cornell scenes load from it)" >&2
  exit 2
fi
MIXED=scripts/ident-scenes/mixed.pbrt

# scene|selectors (the scene field may carry scene options)
SCENES=(
  "cornell|uniform power"
  "cornell-phong|uniform bvh"
  "dense --triangles 20000|uniform"
  "many-open --light-count 2000|uniform power bvh spatial"
  "many-rooms --rooms 3|uniform bvh adaptive wald"
  "many-mesh|uniform power bvh exhaustive"
  "$MIXED|uniform power bvh"
  "tests/data/bulb/bulb.pbrt|uniform bvh"
)
STRATEGIES=(
  "bsdf"
  "light-area"
  "light-solid-angle"
  "mis"
  "mis --mis balance"
  "mis --mis-light area"
)
PATTERNS=(stratified sobol random)
SHADOW=(1 2)
# Extra options tried once per scene (other code paths: per-lane BSDF sampling of diffuse
# receivers, a sample count that is no multiple of the packet).
EXTRAS=("--spp 5 --bsdf-sampling uniform" "--spp 5 --bsdf-sampling cosine"
  "--spp 3 --shadow-rays 3")
if [ "$QUICK" = 1 ]; then
  PATTERNS=(stratified sobol)
fi

total=0 same=0 differ=0
run() { # name, args...
  local name=$1; shift
  total=$((total + 1))
  local b
  for b in old new; do
    local bin=$OLD
    [ $b = new ] && bin=$NEW
    rm -f "$OUT/$b/$name.pfm"
    if ! "$bin" render "$@" --quiet -o "$OUT/$b/$name.pfm" >"$OUT/$b/$name.log" 2>&1; then
      differ=$((differ + 1))
      echo "FAILED ($b) $name: render $*"
      sed 's/^/    /' "$OUT/$b/$name.log"
      return
    fi
  done
  if cmp -s "$OUT/old/$name.pfm" "$OUT/new/$name.pfm"; then
    same=$((same + 1))
  else
    differ=$((differ + 1))
    echo "DIFFER $name: render $*"
    "$NEW" compare "$OUT/new/$name.pfm" "$OUT/old/$name.pfm" | sed 's/^/    /'
  fi
}

for entry in "${SCENES[@]}"; do
  scene=${entry%%|*}
  selectors=${entry#*|}
  # shellcheck disable=SC2206
  scene_args=($scene)
  tag=$(basename "${scene_args[0]}" .pbrt)
  [ "$QUICK" = 1 ] && selectors=${selectors%% *}
  for sel in $selectors; do
    for st in "${STRATEGIES[@]}"; do
      for pat in "${PATTERNS[@]}"; do
        for m in "${SHADOW[@]}"; do
          [ "$QUICK" = 1 ] && [ "$m" = 2 ] && [ "$tag" != cornell ] && continue
          # shellcheck disable=SC2206
          st_args=($st)
          name="$tag-$sel-${st// /_}-$pat-m$m"
          run "$name" "${scene_args[@]}" --res 40x30 --spp 5 --seed 7 \
            --strategy "${st_args[@]}" --light-selection "$sel" --pattern "$pat" \
            --shadow-rays "$m"
        done
      done
    done
  done
  for ex in "${EXTRAS[@]}"; do
    # shellcheck disable=SC2206
    ex_args=($ex)
    name="$tag-extra-${ex// /_}"
    run "$name" "${scene_args[@]}" --res 40x30 --seed 3 "${ex_args[@]}"
  done
done
echo "ident: $same of $total identical, $differ differ"
[ "$differ" = 0 ] && echo "ALL IDENTICAL"
[ "$differ" = 0 ]
