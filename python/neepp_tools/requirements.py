"""What the parts of neepp's command line written in Python need from their interpreter, checked before
anything imports it: a missing module is then one message naming what is missing and the one command that
installs it, not a Python traceback (a user who ran only the demo has no .venv)."""
from __future__ import annotations

import importlib.util
import os
import sys

from . import REPO_ROOT


def _present(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def missing(required: dict[str, str], any_of: list[dict[str, str]] = ()) -> list[str]:
    """The pip names of what is absent: each of `required` ({module: pip name}), and for each group of
    `any_of` (modules of which one is enough) all of its names, joined by " or "."""
    out = [pip for module, pip in required.items() if not _present(module)]
    for group in any_of:
        if not any(_present(module) for module in group):
            out.append(" or ".join(group.values()))
    return out


def require(command: str, required: dict[str, str], any_of: list[dict[str, str]] = ()) -> None:
    """Exits (status 1) with the message, when anything is missing."""
    absent = missing(required, any_of)
    if not absent:
        return
    setup = REPO_ROOT / "scripts" / "setup_python.sh"
    lines = [
        f"neepp: error: {command} runs in Python ({sys.executable}), which lacks: {', '.join(absent)}.",
        f"Install them (into {REPO_ROOT / '.venv'}, which neepp then uses) with:",
        f"    {setup}",
    ]
    if os.environ.get("NEEPP_PYTHON"):
        lines.append(f"and unset NEEPP_PYTHON (it chose {os.environ['NEEPP_PYTHON']}), "
                     f"or point it at {REPO_ROOT / '.venv' / 'bin' / 'python'}.")
    print("\n".join(lines), file=sys.stderr)
    sys.exit(1)


# What `neepp compare` imports: numpy throughout, pillow for the page's images, matplotlib for its plots, and
# mitsuba or OpenEXR to read EXR files (NVIDIA FLIP is optional: without it the page has no FLIP column).
COMPARE_REQUIRED = {"numpy": "numpy", "PIL": "pillow", "matplotlib": "matplotlib"}
COMPARE_ANY_OF = [{"mitsuba": "mitsuba", "OpenEXR": "openexr"}]

# What `neepp view` imports: numpy, and aiohttp for its web server; it renders through the neepp package
# itself (require_package).
VIEW_REQUIRED = {"numpy": "numpy", "aiohttp": "aiohttp"}


def require_package(command: str) -> None:
    """Exits (status 1) with the command that installs the neepp package into this Python, when it lacks it:
    scripts/setup_python.sh installs the modules the tools import, not the package built from the checkout."""
    if _present("neepp._neepp"):
        return
    print("\n".join([
        f"neepp: error: {command} renders through the neepp Python package, which {sys.executable} lacks.",
        "Build and install it from this checkout (scripts/test.sh does it too) with:",
        f"    {sys.executable} -m pip install --no-build-isolation {REPO_ROOT}",
    ]), file=sys.stderr)
    sys.exit(1)
