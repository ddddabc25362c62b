#!/usr/bin/env bash
# The whole test suite: installs what it needs (Debian packages, the Python venv with Mitsuba 3),
# builds, then runs the C++ tests (ctest, then again under ASan+UBSan, and the parallel parts under TSan),
# the fuzz targets for 10 s each (a smoke test of each harness: the long runs are fuzz/README.md's),
# and the Python tests (pytest: CLI, the Python package, comparison with Mitsuba 3).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# Each stage's wall time, printed as it ends and summed up at the end: CI's budget is spent by stage.
TIMES=()
stage() {
  local name="$1" t0=$SECONDS
  shift
  "$@"
  TIMES+=("$(printf '%-12s %5d s' "$name" $((SECONDS - t0)))")
  echo "test.sh: stage $name took $((SECONDS - t0)) s"
}
# valgrind: tests/python/test_instructions.py runs bench/instructions.py, which counts instructions with it;
# chromium: tests/python/test_compare.py opens neepp compare's page in it (headless).
stage deps "$ROOT/scripts/install_deps.sh" valgrind chromium
stage python "$ROOT/scripts/setup_python.sh"
stage build "$ROOT/scripts/build.sh"
# The neepp Python package (tests/python/test_package.py, test_distributed.py), installed by pip from build/:
# the library objects just built are reused (native, as the CLI's), so only the extension module compiles.
# A user's plain `pip install .` compiles everything again for the x86-64-v2 baseline in build/python-*.
stage package "$ROOT/.venv/bin/python" -m pip install -q --no-build-isolation -C build-dir=build \
  -C cmake.define.NEEPP_MARCH=native -C cmake.define.NEEPP_TESTS=ON "$ROOT"
# The instruction-count test runs neepp under valgrind, which cannot run a -march=native build of an
# AVX-512 CPU: there it gets a build for x86-64-v3. Where valgrind runs the native build (no AVX-512), the
# test uses that one and the second build is skipped.
if ! "$ROOT/.venv/bin/python" - "$ROOT" <<'PY'
import sys
from pathlib import Path
root = Path(sys.argv[1])
sys.path.insert(0, str(root / "bench"))
import instructions
sys.exit(0 if instructions.valgrind_problem(root / "build" / "neepp") is None else 1)
PY
then
  stage valgrind-build "$ROOT/scripts/build_valgrind.sh"
fi
stage ctest ctest --test-dir "$ROOT/build" --output-on-failure -j2
# The C++ tests again under AddressSanitizer + UndefinedBehaviorSanitizer (clang), then each fuzz target
# of fuzz/ for 10 s: both in build-sanitize/.
stage sanitizers "$ROOT/scripts/test_sanitizers.sh"
# ThreadSanitizer over the render loop's and the visibility map's tests, with TBB rebuilt for it.
stage tsan "$ROOT/scripts/test_tsan.sh"
stage fuzz "$ROOT/scripts/fuzz.sh" 10
cd "$ROOT"
# Two workers (pytest-xdist): much of a test's time leaves a core idle (Mitsuba's JIT, loading, a process
# starting, a server waited on). Each module runs in one worker (--dist loadfile: tests/python/conftest.py).
NEEPP_BIN="$ROOT/build/neepp" stage pytest "$ROOT/.venv/bin/python" -m pytest tests/python -q -rs --durations=30 \
  -n 2 --dist loadfile
printf 'test.sh: %s\n' "${TIMES[@]}"
