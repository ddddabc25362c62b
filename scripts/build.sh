#!/usr/bin/env bash
# Configure and build neepp (Release) into build/. Usage: scripts/build.sh [extra cmake args]
#
# The build is profile-guided (see NEEPP_PGO in CMakeLists.txt): an instrumented neepp is built into
# build/pgo-generate, renders the project's own scenes (scripts/pgo_train.sh), and build/ is then compiled
# with what it recorded; about 4 % more samples/s, for about a minute more of building.
# NEEPP_PGO=0 scripts/build.sh builds once, without a profile (quicker while editing).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ "${NEEPP_PGO:-1}" == 0 ]]; then
  cmake -S "$ROOT" -B "$ROOT/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DNEEPP_PGO= "$@" >/dev/null
else
  GEN="$ROOT/build/pgo-generate" PROFILE="$ROOT/build/pgo-profile"
  cmake -S "$ROOT" -B "$GEN" -G Ninja -DCMAKE_BUILD_TYPE=Release -DNEEPP_TESTS=OFF \
    -DNEEPP_PGO=generate -DNEEPP_PGO_DIR="$PROFILE" "$@" >/dev/null
  cmake --build "$GEN" --target neepp -j"$(nproc)"
  rm -rf "$PROFILE"  # a fresh record: counts from an older binary would not match this one's code
  echo "-- training run for the profile-guided build (scripts/pgo_train.sh)"
  "$ROOT/scripts/pgo_train.sh" "$GEN/neepp" "$GEN/training"
  cmake -S "$ROOT" -B "$ROOT/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DNEEPP_PGO=use -DNEEPP_PGO_DIR="$PROFILE" "$@" >/dev/null
fi
cmake --build "$ROOT/build" -j"$(nproc)"
