#!/usr/bin/env bash
# Create the project's Python virtualenv (.venv, git-ignored) with the tools used by
# python/neepp_tools, tests/python and bench/: numpy, pytest, matplotlib, pillow, Mitsuba 3
# (the peer renderer), flip-evaluator (NVIDIA FLIP, for neepp compare), and nanobind and scikit-build-core,
# with which scripts/test.sh installs the neepp package into it (pip install --no-build-isolation), Ray
# (neepp.distributed), aiohttp (neepp view's web server) and pytest-xdist (scripts/test.sh runs pytest
# in two workers). Also installs libllvm19 (Debian 12 main) for Mitsuba's llvm_ad_rgb variant, which must
# then be run with DRJIT_LIBLLVM_PATH set (neepp_tools.runner does it).
# Idempotent; safe to rerun. Usage: scripts/setup_python.sh [VENV_DIR]
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${1:-$ROOT/.venv}"
PYTHON="${PYTHON:-python3}"

# Versions that are known to install and work here (Python 3.11, Debian 12, x86-64).
REQS=(
  "numpy>=1.24,<3"
  "pytest>=7"
  "matplotlib>=3.7"
  "pillow>=9"
  "mitsuba==3.9.*"
  "flip-evaluator>=1.7"
  "nanobind>=2.4"
  "scikit-build-core>=0.10"
  "ray>=2.9"
  "aiohttp>=3.9"
  "pytest-xdist>=3.5"
)

# libllvm19 for the llvm variant (LLVM 14/15 make Dr.Jit abort). Skip apt when present.
if ! dpkg-query -W -f='${Status}' libllvm19 2>/dev/null | grep -q "install ok installed"; then
  bash "$ROOT/scripts/install_deps.sh" libllvm19 || echo "setup_python: WARNING: could not install libllvm19; only scalar_rgb will work" >&2
fi
# python3-venv is needed for `python3 -m venv` with Debian's python.
if ! "$PYTHON" -c "import ensurepip, venv" 2>/dev/null; then
  bash "$ROOT/scripts/install_deps.sh"
fi

if [ ! -x "$VENV/bin/python" ]; then
  echo "setup_python: creating $VENV"
  "$PYTHON" -m venv "$VENV"
fi

if "$VENV/bin/python" - "${REQS[@]}" <<'PY' 2>/dev/null
import sys
from importlib.metadata import version
want = {"numpy": None, "pytest": None, "matplotlib": None, "pillow": None, "mitsuba": "3.9.", "flip-evaluator": None,
        "nanobind": None, "scikit-build-core": None, "ray": None, "aiohttp": None, "pytest-xdist": None}
for name, prefix in want.items():
    v = version(name)
    if prefix and not v.startswith(prefix):
        sys.exit(1)
PY
then
  echo "setup_python: $VENV already has numpy, pytest, matplotlib, pillow, mitsuba 3.9, flip-evaluator, nanobind, scikit-build-core, ray, aiohttp, pytest-xdist"
else
  "$VENV/bin/python" -m pip install -q --upgrade pip
  "$VENV/bin/python" -m pip install -q "${REQS[@]}"
fi

"$VENV/bin/python" -c "import mitsuba, drjit, numpy, matplotlib, PIL, pytest; print('setup_python: mitsuba', mitsuba.__version__, 'drjit', drjit.__version__, 'numpy', numpy.__version__)"
LLVM=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
if [ -e "$LLVM" ]; then
  echo "setup_python: for llvm_ad_rgb use DRJIT_LIBLLVM_PATH=$LLVM"
fi
