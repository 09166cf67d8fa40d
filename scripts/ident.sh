#!/usr/bin/env bash
# Bit-identity check for refactors: render a grid of scenes × light selectors × strategies (and
# every sample pattern, MIS variants, several shadow rays) with two penumbra binaries at a small
# resolution and require identical images: the PFM files byte for byte, and `penumbra compare`
# (printed on a mismatch) with MSE and relMSE 0.
#
# Usage: scripts/ident.sh OLD_BIN NEW_BIN [OUT_DIR]
#   e.g. cp target/release/penumbra /tmp/penumbra-before; (change, cargo build --release);
#        scripts/ident.sh /tmp/penumbra-before target/release/penumbra
# Environment: RES (default 64x48), SPP (default 4), SCENES, SELECTORS, STRATEGIES, PATTERNS
# override the lists below. Exits 1 if any image differs or any render fails.
set -uo pipefail
OLD=${1:?usage: scripts/ident.sh OLD_BIN NEW_BIN [OUT_DIR]}
NEW=${2:?usage: scripts/ident.sh OLD_BIN NEW_BIN [OUT_DIR]}
OUT=${3:-$(mktemp -d -t penumbra-ident.XXXXXX)}
RES=${RES:-64x48}
SPP=${SPP:-4}
SCENES=${SCENES:-"cornell cornell-phong dense many-open many-rooms many-mesh"}
SELECTORS=${SELECTORS:-"uniform power spatial adaptive wald bvh exhaustive"}
STRATEGIES=${STRATEGIES:-"bsdf light-area light-solid-angle mis"}
PATTERNS=${PATTERNS:-"fixed random grid stratified lhs sobol"}
mkdir -p "$OUT/old" "$OUT/new"

total=0
bad=0
# check NAME ARGS...: render with both binaries and compare.
check() {
  local name=$1
  shift
  total=$((total + 1))
  for side in old new; do
    local bin=$OLD
    [ "$side" = new ] && bin=$NEW
    if ! "$bin" render "$@" --res "$RES" --spp "$SPP" --quiet -o "$OUT/$side/$name.pfm" \
      >"$OUT/$side/$name.log" 2>&1; then
      echo "FAIL  $name: $side render failed: $(tail -1 "$OUT/$side/$name.log")"
      bad=$((bad + 1))
      return
    fi
  done
  if cmp -s "$OUT/old/$name.pfm" "$OUT/new/$name.pfm"; then
    echo "same  $name"
  else
    echo "DIFF  $name: $("$NEW" compare "$OUT/new/$name.pfm" "$OUT/old/$name.pfm" | tr '\n' ' ')"
    bad=$((bad + 1))
  fi
}

for scene in $SCENES; do
  for sel in $SELECTORS; do
    for strat in $STRATEGIES; do
      check "$scene-$sel-$strat" "$scene" --light-selection "$sel" --strategy "$strat"
    done
  done
  # The default selector (whatever the binary's default is: both must agree).
  check "$scene-default-mis" "$scene"
done
for pat in $PATTERNS; do
  check "cornell-$pat" cornell --pattern "$pat"
  check "cornell-phong-$pat-2rays" cornell-phong --pattern "$pat" --shadow-rays 2
done
check "cornell-mis-area-balance" cornell --mis-light area --mis balance
check "cornell-phong-cosine-lobes" cornell-phong --bsdf-sampling cosine --strategy bsdf
check "cornell-seed7" cornell --seed 7 --shadow-rays 3
check "many-rooms-bvh-3rays" many-rooms --light-selection bvh --shadow-rays 3

echo "$((total - bad)) of $total identical (images in $OUT)"
[ "$bad" -eq 0 ]
