#!/usr/bin/env bash
# The training run of the profile-guided build: renders the project's own scenes (no download) with the
# instrumented neepp given as $1, so that its profile covers what rendering does: every BSDF, texture and
# emitter type (scenes/materials), both samplers and all reconstruction filters, path tracing with and
# without NEE, each NEE++ shadow-ray policy and the light-selection strategies. Small images, ~30 s.
# Usage: scripts/pgo_train.sh INSTRUMENTED_NEEPP WORK_DIR
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$1"; OUT="$2"
mkdir -p "$OUT"
render() { "$BIN" render "$@" --quiet; }
# The materials scene's bitmap and environment map: a small render of the door-ajar room, as PNG and EXR.
render "$ROOT/scenes/door-ajar/scene.xml" -o "$OUT/door-ajar.exr" --spp 4 -D resx=64 -D resy=48
MAT=("$ROOT/scenes/materials/scene.xml" -D "texture=$OUT/door-ajar.png" -D "envmap=$OUT/door-ajar.exr")
render "${MAT[@]}" -o "$OUT/materials.exr" --spp 16 -D resx=128 -D resy=96 -D max_depth=17
render "${MAT[@]}" -o "$OUT/materials-sobol.exr" --spp 8 -D resx=96 -D resy=64 --sampler sobol --rfilter box
render "${MAT[@]}" -o "$OUT/materials-bsdf.exr" --spp 8 -D resx=96 -D resy=64 -I nee=false --rfilter tent
for policy in neepp neepp-adaptive neepp-cv; do
  render "$ROOT/scenes/door-ajar/scene.xml" -o "$OUT/door-ajar-$policy.exr" --spp 16 -D resx=96 -D resy=72 \
    -I shadow_rays=$policy
done
for sampler in spatial bvh visibility visibility-bvh; do
  render "$ROOT/scenes/office/scene.xml" -o "$OUT/office-$sampler.exr" --spp 8 -D resx=96 -D resy=64 \
    -I light_sampler=$sampler
done
render "$ROOT/scenes/courtyard/scene.xml" -o "$OUT/courtyard.exr" --spp 8 -D resx=96 -D resy=64 \
  -D "envmap=$OUT/door-ajar.exr" -I light_sampler=visibility -I shadow_rays=neepp
