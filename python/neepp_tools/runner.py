"""Run the neepp CLI and Mitsuba 3 on a scene; read back image + stats.

Both renderers run in child processes. Peak memory of a child is taken from os.wait4's rusage
(ru_maxrss), besides what the renderer reports itself. Mitsuba runs through
``python -m neepp_tools.mitsuba_worker`` (see there) so that the llvm variant's hang-at-exit quirk
cannot block the caller: the worker ends with os._exit, and a worker still alive after it wrote its
JSON is killed.
"""
from __future__ import annotations

import functools
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import REPO_ROOT
from .exr import read_exr

LLVM_PATH = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
CACHE_DIR = REPO_ROOT / ".cache" / "mitsuba"


@dataclass
class RenderResult:
    image: np.ndarray
    stats: dict
    wall_s: float
    peak_rss_mb: float  # child's ru_maxrss from wait4
    exr_path: Path
    log: str = ""
    cached: bool = False
    extra: dict = field(default_factory=dict)


class RenderError(RuntimeError):
    pass


# ----------------------------------------------------------------------------------------------
# child process helper


def _run_child(cmd, env=None, timeout=None, done_file: Path | None = None, grace_s: float = 20.0,
               cwd=None):
    """Run cmd, return (returncode, output, wall_s, ru_maxrss_mb).

    If done_file appears and the child does not exit within grace_s afterwards, it is killed
    (returncode then is 0 if done_file exists). On timeout the child is killed and RenderError raised.
    """
    t0 = time.perf_counter()
    with tempfile.TemporaryFile(mode="w+b") as logf:
        p = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=logf, stderr=subprocess.STDOUT,
                             start_new_session=True)
        rc = None
        ru = None
        done_seen_at = None
        killed_after_done = False
        while True:
            pid, status, ru_ = os.wait4(p.pid, os.WNOHANG)
            if pid == p.pid:
                ru = ru_
                rc = os.waitstatus_to_exitcode(status)
                p.returncode = rc
                break
            now = time.perf_counter()
            if done_file is not None and done_seen_at is None and Path(done_file).exists():
                done_seen_at = now
            if done_seen_at is not None and now - done_seen_at > grace_s:
                killed_after_done = True
                _kill(p)
                continue
            if timeout is not None and now - t0 > timeout:
                _kill(p)
                pid, status, ru = os.wait4(p.pid, 0)
                p.returncode = os.waitstatus_to_exitcode(status)
                logf.seek(0)
                out = logf.read().decode(errors="replace")
                raise RenderError(f"timed out after {timeout:.0f} s: {' '.join(map(str, cmd))}\n{out[-4000:]}")
            time.sleep(0.05)
        wall = time.perf_counter() - t0
        logf.seek(0)
        out = logf.read().decode(errors="replace")
    if killed_after_done:
        rc = 0
        out += "\n[runner] child killed after it wrote its results (hang at exit)\n"
    maxrss_mb = ru.ru_maxrss / 1024.0 if ru is not None else float("nan")
    return rc, out, wall, maxrss_mb


def _kill(p):
    try:
        os.killpg(p.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


# ----------------------------------------------------------------------------------------------
# neepp


def find_neepp() -> Path | None:
    """The neepp binary: $NEEPP_BIN if set (only it), else <repo>/build/neepp. None if it is not there."""
    env = os.environ.get("NEEPP_BIN")
    c = Path(env) if env else REPO_ROOT / "build" / "neepp"
    if c.is_file() and os.access(c, os.X_OK):
        return c.resolve()
    return None


def run_neepp(scene, out_exr, *, spp: int | None = None, time_s: float | None = None,
              resx: int | None = None, resy: int | None = None, max_depth: int | None = None,
              seed: int | None = 0, threads: int | None = None, integrator: str | None = None,
              integrator_args: dict | None = None, defines: dict | None = None,
              binary=None, timeout: float | None = None, quiet: bool = True,
              extra_args: list | None = None, env: dict | None = None) -> RenderResult:
    """Render scene with ``neepp render`` and read back OUT.exr and the stats JSON. env: variables set
    for the child on top of this process's environment."""
    binary = Path(binary) if binary else find_neepp()
    if binary is None:
        raise RenderError("neepp binary not found (set NEEPP_BIN or build <repo>/build/neepp)")
    out_exr = Path(out_exr)
    out_exr.parent.mkdir(parents=True, exist_ok=True)
    stats_path = out_exr.with_suffix(".stats.json")
    for p in (out_exr, stats_path):
        if p.exists():
            p.unlink()
    cmd = [str(binary), "render", str(scene), "-o", str(out_exr), "--stats", str(stats_path)]
    if spp is not None:
        cmd += ["--spp", str(int(spp))]
    if time_s is not None:
        cmd += ["--time", str(time_s)]
    if seed is not None:
        cmd += ["--seed", str(int(seed))]
    if threads:
        cmd += ["--threads", str(int(threads))]
    if integrator:
        cmd += ["--integrator", integrator]
    d = dict(defines or {})
    if resx is not None:
        d["resx"] = resx
    if resy is not None:
        d["resy"] = resy
    if max_depth is not None:
        d["max_depth"] = max_depth
    for k, v in d.items():
        cmd += ["-D", f"{k}={v}"]
    for k, v in (integrator_args or {}).items():
        cmd += ["-I", f"{k}={v}"]
    if quiet:
        cmd.append("--quiet")
    cmd += [str(x) for x in (extra_args or [])]
    rc, out, wall, rss = _run_child(cmd, env=dict(os.environ, **env) if env else None, timeout=timeout)
    if rc != 0 or not out_exr.exists():
        raise RenderError(f"neepp failed (rc={rc}): {' '.join(cmd)}\n{out[-4000:]}")
    stats = json.loads(stats_path.read_text()) if stats_path.exists() else {}
    stats.setdefault("renderer", "neepp")
    return RenderResult(read_exr(out_exr), stats, wall, rss, out_exr, out)


# ----------------------------------------------------------------------------------------------
# Mitsuba 3


def mitsuba_python() -> str:
    """Python interpreter that has mitsuba: $NEEPP_MITSUBA_PYTHON, this one, or <repo>/.venv."""
    env = os.environ.get("NEEPP_MITSUBA_PYTHON")
    if env:
        return env
    try:
        import importlib.util

        if importlib.util.find_spec("mitsuba") is not None:
            return sys.executable
    except (ImportError, ValueError):
        pass
    venv = REPO_ROOT / ".venv" / "bin" / "python"
    return str(venv) if venv.exists() else sys.executable


def mitsuba_available(variant: str = "scalar_rgb") -> tuple[bool, str]:
    """(ok, reason). Checks mitsuba imports and, for llvm variants, that libLLVM 19 is present."""
    py = mitsuba_python()
    code = "import mitsuba, sys; sys.stdout.write(mitsuba.__version__)"
    try:
        r = subprocess.run([py, "-c", code], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as e:
        return False, f"cannot run {py}: {e}"
    if r.returncode != 0:
        return False, f"mitsuba is not importable by {py} (run scripts/setup_python.sh)"
    if variant.startswith("llvm") and not (os.environ.get("DRJIT_LIBLLVM_PATH") or os.path.exists(LLVM_PATH)):
        return False, f"{LLVM_PATH} missing (apt-get install libllvm19)"
    return True, r.stdout.strip()


@functools.lru_cache(maxsize=None)
def mitsuba_version() -> str:
    """Version of mitsuba in mitsuba_python() ('' if not importable)."""
    code = "import importlib.metadata as m, sys; sys.stdout.write(m.version('mitsuba'))"
    try:
        r = subprocess.run([mitsuba_python(), "-c", code], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    return r.stdout.strip() if r.returncode == 0 else ""


def _cache_key(scene, **kw) -> str:
    scene = Path(scene).resolve()
    st = scene.stat()
    # A parameter naming a file (a texture, an environment map) counts by its content, which a test may
    # write anew each run.
    files = {k: hashlib.sha1(Path(v).read_bytes()).hexdigest() for k, v in (kw.get("defines") or {}).items()
             if Path(v).is_file()}
    key = {"scene": str(scene), "size": st.st_size, "mtime": int(st.st_mtime), "mitsuba": mitsuba_version(), **kw}
    if files:
        key["files"] = files
    blob = json.dumps(key, sort_keys=True)
    return hashlib.sha1(blob.encode()).hexdigest()[:16]


def run_mitsuba(scene, out_exr=None, *, variant: str = "llvm_ad_rgb", resx: int | None = None,
                resy: int | None = None, spp: int = 16, max_depth: int = 17, seed: int = 0,
                integrator: str = "path", spp_per_pass: int = 0, threads: int = 0,
                defines: dict | None = None, timeout: float | None = None,
                cache: bool | Path = False, as_published: bool = False) -> RenderResult:
    """Render scene with Mitsuba 3 in a child process; returns image + timing stats.

    as_published=True passes the scene only `defines` (not resx/resy, max_depth, integrator) and renders
    its own integrator, at spp.

    cache=True (or a directory) reuses a previous render with identical parameters, keyed by scene
    path/size/mtime and all render parameters; the image is then stored under the cache directory.
    """
    kw = dict(variant=variant, resx=resx, resy=resy, spp=int(spp), max_depth=int(max_depth),
              seed=int(seed), integrator=integrator)
    if defines:  # only when given, so that the keys of existing cached renders stay valid
        kw["defines"] = {k: str(v) for k, v in defines.items()}
    if as_published:
        kw["as_published"] = True
    cache_dir = None
    if cache:
        cache_dir = Path(cache) if not isinstance(cache, bool) else CACHE_DIR
        key = f"{Path(scene).parent.name}_{_cache_key(scene, **kw)}"
        c_exr, c_json = cache_dir / f"{key}.exr", cache_dir / f"{key}.json"
        if c_exr.exists() and c_json.exists():
            stats = json.loads(c_json.read_text())
            img = read_exr(c_exr)
            if out_exr is not None:
                Path(out_exr).parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(c_exr, out_exr)
            return RenderResult(img, stats, 0.0, stats.get("peak_rss_mb", float("nan")),
                                Path(out_exr) if out_exr else c_exr, cached=True)
        if out_exr is None:
            # Rendered beside the cache under a name of this process, then moved into place: two test
            # processes (pytest -n) asking for the same render each write whole files, never half of one.
            out_exr = cache_dir / f".{key}.{os.getpid()}.exr"
    if out_exr is None:
        raise ValueError("out_exr is required without cache")
    out_exr = Path(out_exr)
    out_exr.parent.mkdir(parents=True, exist_ok=True)
    json_path = out_exr.with_suffix(".mitsuba.json")
    for p in (out_exr, json_path):
        if p.exists():
            p.unlink()
    cmd = [mitsuba_python(), "-m", "neepp_tools.mitsuba_worker", "--scene", str(scene),
           "--out", str(out_exr), "--json", str(json_path), "--variant", variant,
           "--spp", str(int(spp)), "--max-depth", str(int(max_depth)), "--seed", str(int(seed)),
           "--integrator", integrator]
    if resx:
        cmd += ["--resx", str(int(resx))]
    if resy:
        cmd += ["--resy", str(int(resy))]
    if spp_per_pass:
        cmd += ["--spp-per-pass", str(int(spp_per_pass))]
    if threads:
        cmd += ["--threads", str(int(threads))]
    for k, v in (defines or {}).items():
        cmd += ["--define", f"{k}={v}"]
    if as_published:
        cmd.append("--as-published")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO_ROOT / "python")] +
                                        ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in env and os.path.exists(LLVM_PATH):
        env["DRJIT_LIBLLVM_PATH"] = LLVM_PATH
    rc, out, wall, rss = _run_child(cmd, env=env, timeout=timeout, done_file=json_path)
    if rc != 0 or not json_path.exists() or not out_exr.exists():
        raise RenderError(f"mitsuba failed (rc={rc}): {' '.join(cmd)}\n{out[-4000:]}")
    stats = json.loads(json_path.read_text())
    stats["wall_s"] = wall
    stats["peak_rss_mb"] = rss
    if cache_dir is not None:
        cache_dir.mkdir(parents=True, exist_ok=True)
        # The EXR first, then the JSON that marks the entry complete, each by an atomic rename.
        tmp_exr, tmp_json = (cache_dir / f".{key}.{os.getpid()}.{ext}.tmp" for ext in ("exr", "json"))
        shutil.copyfile(out_exr, tmp_exr)
        os.replace(tmp_exr, c_exr)
        tmp_json.write_text(json.dumps(stats, indent=2))
        os.replace(tmp_json, c_json)
        if out_exr.name.startswith(f".{key}."):
            out_exr.unlink()
            json_path.unlink(missing_ok=True)
            out_exr = c_exr
    return RenderResult(read_exr(out_exr), stats, wall, rss, out_exr, out)
