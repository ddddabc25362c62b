"""pytest setup for the Python test suite (tests/python).

Puts <repo>/python on sys.path and offers fixtures that locate the neepp binary, the shared scenes
and Mitsuba 3, skipping with a clear message when one is missing. Run with the project's venv:

    scripts/setup_python.sh && .venv/bin/python -m pytest tests/python -v -s
"""
from __future__ import annotations

import fcntl
import os
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import SCENES_DIR, runner  # noqa: E402


@pytest.fixture(scope="session")
def scenes_dir() -> Path:
    d = Path(os.environ.get("NEEPP_SCENES_DIR", SCENES_DIR))
    if not (d / "cornell-box" / "scene.xml").exists():
        pytest.skip(f"shared scenes not found at {d} (expected ../shared/scenes beside the repo)")
    return d


@pytest.fixture(scope="session")
def neepp_bin() -> Path:
    b = runner.find_neepp()
    if b is None:
        pytest.skip("neepp binary not found: set NEEPP_BIN or build it into build/neepp "
                    "(cmake -S . -B build -G Ninja && cmake --build build)")
    return b


@pytest.fixture(scope="session")
def mitsuba_variant() -> str:
    """llvm_ad_rgb when libLLVM 19 is there (fast), else scalar_rgb."""
    ok, why = runner.mitsuba_available("llvm_ad_rgb")
    if ok:
        return "llvm_ad_rgb"
    ok, why2 = runner.mitsuba_available("scalar_rgb")
    if ok:
        return "scalar_rgb"
    pytest.skip(f"Mitsuba 3 not usable: {why2}")


@pytest.fixture(scope="session")
def work_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("vs_mitsuba")


# Modules that start a local Ray instance: never two at once, in any worker (a file lock, below).
_RAY_MODULES = {"test_distributed", "test_distributed_checkpoint"}


@pytest.fixture(scope="module", autouse=True)
def _one_ray_module_at_a_time(request):
    # scripts/test.sh runs the suite in two pytest-xdist workers, each module in one of them (--dist
    # loadfile: its module fixtures, a server or a memoized reference render, start once, and its files in
    # .cache/<module>/ have one writer). Two local Ray instances at once on two cores would starve each
    # other's actors of the time their tests allow; the lock keeps them one after the other.
    if request.module.__name__.rsplit(".", 1)[-1] not in _RAY_MODULES:
        yield
        return
    lock = REPO / ".cache" / "ray.lock"
    lock.parent.mkdir(parents=True, exist_ok=True)
    with open(lock, "w") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


def _sigint_ignored() -> bool:
    """Whether this process ignores SIGINT (the kernel's view: a C library can set SIG_IGN behind Python's back)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("SigIgn:"):
                return bool(int(line.split()[1], 16) & (1 << (2 - 1)))
    except OSError:
        pass
    return False


@pytest.fixture(autouse=True)
def _leaves_ctrl_c_as_it_found_it(request):
    # A process inherits an ignored SIGINT, and Python then never raises KeyboardInterrupt in it: a test that
    # leaves its worker ignoring SIGINT silently breaks every later test of Ctrl-C in that worker (the
    # Ctrl-C test of test_package.py failed so, depending on which modules a worker had run before it).
    before = _sigint_ignored()
    yield
    if _sigint_ignored() and not before:
        import signal
        signal.signal(signal.SIGINT, signal.default_int_handler)
        pytest.fail(f"{request.node.nodeid} left this process ignoring SIGINT (restored for the tests after it)")
