#!/usr/bin/env bash
# Side-by-side speed and error of penumbra and Mitsuba 3 (llvm variant) on the Cornell box:
# 512², 64 spp, direct lighting with MIS (and light/BSDF sampling alone), both judged against
# ../shared/reference/cornell-direct-mis-8192spp.exr with `penumbra compare`; and path tracing
# (Mitsuba's `path`, max depth -1; penumbra's `--integrator path`, the file's maxdepth 65, MIS)
# against ../shared/reference/cornell-path-4096spp.exr. MODES="mis emitter bsdf path" picks.
#
# Both films splat: Mitsuba's hdrfilm adds each sample to every pixel its tent filter reaches
# and divides by the weight sum; penumbra does the same with --splat (FILM=fis for its filter
# importance sampling, which counts each sample in one pixel: the same mean, more noise per
# pixel).
#
# Needs a Mitsuba venv (python3 -m venv V && V/bin/pip install mitsuba numpy) and Debian's
# libllvm19. Usage: scripts/compare-mitsuba.sh [VENV] [PROFILE]   (defaults: /work/mitsuba-venv, release)
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${1:-/work/mitsuba-venv}
PROFILE=${2:-release}
SHARED=../shared
OUT=${OUT:-target/compare-mitsuba}
mkdir -p "$OUT"
cargo build --profile "$PROFILE" --bin penumbra >/dev/null
BIN=target/$PROFILE/penumbra
REF=$SHARED/reference/cornell-direct-mis-8192spp.exr
XML=$OUT/scene512.xml
sed -e 's/name="resy" value="1024"/name="resy" value="512"/' \
    -e 's/name="resx" value="1024"/name="resx" value="512"/' \
    "$SHARED/scenes/cornell-box-bitterli/scene_v3.xml" > "$XML"
# The scene file refers to no external assets, so it renders from the copy.
for mode in ${MODES:-mis emitter bsdf path}; do
  theirs=""
  REF=$SHARED/reference/cornell-direct-mis-8192spp.exr
  case $mode in
    mis) ours="--integrator direct --strategy mis --mis-light area" ;;
    emitter) ours="--integrator direct --strategy light-area" ;;
    bsdf) ours="--integrator direct --strategy bsdf" ;;
    path) ours="--integrator path --strategy mis"; theirs="--max-depth -1"
      REF=$SHARED/reference/cornell-path-4096spp.exr ;;
  esac
  # Mitsuba: the second of two runs (the first includes JIT compilation).
  # shellcheck disable=SC2086
  "$VENV/bin/python" "$SHARED/peers/mitsuba/render.py" "$XML" $mode 64 "$OUT/mitsuba-$mode.exr" \
    --variant llvm_ad_rgb --repeat 2 --seed 1 $theirs | grep TIME | tail -1
  # Uniform light selection, as in the README's table: the box's one quad is two equal
  # triangles, so it draws what Mitsuba's power-weighted emitter choice draws, without the
  # default light BVH's per-sample cost (docs/many-lights.md).
  film=""; [ "${FILM:-splat}" = splat ] && film="--splat"
  # shellcheck disable=SC2086
  /usr/bin/time -f "penumbra TIME %e s wall, %U s user, %S s sys (load $(cut -d' ' -f1-3 /proc/loadavg))" \
    $BIN render cornell --spp 64 --seed 1 --quiet --light-selection uniform $ours $film \
    -o "$OUT/penumbra-$mode.exr"
  echo "mitsuba $mode vs reference:";  $BIN compare "$OUT/mitsuba-$mode.exr" "$REF" | grep relMSE
  echo "penumbra $mode vs reference:"; $BIN compare "$OUT/penumbra-$mode.exr" "$REF" | grep relMSE
done
