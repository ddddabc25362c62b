#!/usr/bin/env bash
# Renders a fixed set of configurations with two neepp binaries and says, for each, whether the two EXRs
# are the same bytes: for changes that must not move an image (a refactor). Covers path with every NEE++
# use, bdpt with and without NEE++ selection, light, pssmlt over bdpt and over path, the sobol sampler, one
# and two threads, every built-in BSDF (scenes/materials) and crops of the evaluation scenes.
# Usage: scripts/same_images.sh OLD_BINARY NEW_BINARY [OUT_DIR]; exits 1 if any image differs.
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OLD=$1 NEW=$2 OUT=${3:-$(mktemp -d)}
S="$ROOT/scenes" SH="$ROOT/../shared/scenes"
TEX="$SH/living-room/TungstenRender.png" ENV="$SH/classroom/textures/sky_sunsky.exr"
mkdir -p "$OUT"
differ=0
run() {  # name, render arguments...
  local name=$1; shift
  "$OLD" render "$@" -o "$OUT/$name.old.exr" --png none --quiet >/dev/null 2>&1 || echo "old failed: $name"
  "$NEW" render "$@" -o "$OUT/$name.new.exr" --png none --quiet >/dev/null 2>&1 || echo "new failed: $name"
  if cmp -s "$OUT/$name.old.exr" "$OUT/$name.new.exr"; then echo "same  $name"; else echo "DIFF  $name"; differ=1; fi
}
R="-D resx=64 -D resy=36"
run door_path      "$S/door-ajar/scene.xml" $R --spp 8 --threads 2
run door_neepp     "$S/door-ajar/scene.xml" $R --spp 8 --threads 2 -I shadow_rays=neepp-adaptive
run door_path_t1   "$S/door-ajar/scene.xml" $R --spp 4 --threads 1 -I shadow_rays=neepp
run office_vis     "$S/office/scene.xml" $R --spp 8 --threads 2 -I light_sampler=visibility
run office_auto    "$S/office/scene.xml" $R --spp 8 --threads 2 -I neepp=auto
run office_ris     "$S/office/scene.xml" $R --spp 8 --threads 2 -I ris=4
run corridor_cv    "$S/corridor/scene.xml" $R --spp 8 --threads 2 -I shadow_rays=neepp-cv
run courtyard_wl   "$S/courtyard/scene.xml" $R --spp 8 --threads 2 -I within_light=visibility -I grid_bounds=shading
run door_bdpt      "$S/door-ajar/scene.xml" $R --spp 4 --threads 2 --integrator bdpt
run door_bdptnp    "$S/door-ajar/scene.xml" $R --spp 4 --threads 2 --integrator bdpt -I light_paths=neepp
run door_light     "$S/door-ajar/scene.xml" $R --spp 4 --threads 2 --integrator light
run door_mlt       "$S/door-ajar/scene.xml" $R --spp 4 --threads 2 --integrator pssmlt
run door_mlt_path  "$S/door-ajar/scene.xml" $R --spp 4 --threads 2 --integrator pssmlt -I bidirectional=false
run door_sobol     "$S/door-ajar/scene.xml" $R --spp 8 --threads 2 --sampler sobol
run materials      "$S/materials/scene.xml" -D texture="$TEX" -D envmap="$ENV" -D resx=96 -D resy=64 --spp 8 --threads 2
run materials_bdpt "$S/materials/scene.xml" -D texture="$TEX" -D envmap="$ENV" -D resx=96 -D resy=64 --spp 4 --threads 2 --integrator bdpt
run cbox           "$SH/cornell-box/scene.xml" -D resx=64 -D resy=64 --spp 4 --threads 2
run bathroom       "$SH/bathroom/scene.xml" --crop 200,200,48,48 --spp 4 --threads 2
run living         "$SH/living-room/scene.xml" --crop 300,150,64,48 --spp 4 --threads 2
run staircase      "$SH/staircase/scene.xml" --crop 100,300,48,64 --spp 4 --threads 2
run veach          "$SH/veach-ajar/scene.xml" --crop 300,150,64,48 --spp 4 --threads 2 --integrator bdpt
run classroom      "$SH/classroom/scene.xml" --crop 300,150,64,48 --spp 4 --threads 2
exit $differ
