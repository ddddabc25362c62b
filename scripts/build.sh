#!/usr/bin/env bash
# Configure and build neepp (Release) into build/. Usage: scripts/build.sh [extra cmake args]
#
# NEEPP_PGO=1 scripts/build.sh builds profile-guided instead (see NEEPP_PGO in CMakeLists.txt): an
# instrumented neepp is built into build/pgo-generate, renders the project's own scenes
# (scripts/pgo_train.sh), and build/ is then compiled with what it recorded. About a minute more of
# building for about 1 % more samples/s, inside this machine's noise, so it is not the default.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [[ "${NEEPP_PGO:-0}" == 0 ]]; then
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
