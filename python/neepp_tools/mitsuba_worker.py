"""Render one scene with Mitsuba 3 and write OUT.exr + a timing JSON. Meant to run in its own process
(neepp_tools.runner.run_mitsuba starts it): Dr.Jit's LLVM backend may hang at interpreter exit, so
this script ends with os._exit.

    python -m neepp_tools.mitsuba_worker --scene S.xml --out OUT.exr --json OUT.json \
        [--variant llvm_ad_rgb] [--resx W --resy H] [--spp N] [--max-depth D] [--seed S] \
        [--spp-per-pass P] [--threads T]

The integrator is the scene's (``$integrator``, path by default) with max_depth D; with
--spp-per-pass P it is built as ``{'type': integrator, 'max_depth': D, 'samples_per_pass': P}`` so
that the llvm variant's wavefront stays within memory at high spp (one mi.render call either way).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import time
import traceback

LLVM_DEFAULT = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"


def _peak_memory_mb(ru) -> float:
    """This process's own peak resident set (VmHWM). ru_maxrss is not: Linux folds into it the peak of the
    address space exec replaced, which for a child started by Python's subprocess (vfork, then exec) is
    its parent's, so it reported the benchmark script's size rather than Mitsuba's."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return ru.ru_maxrss / 1024.0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--json", required=True)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--resx", type=int)
    ap.add_argument("--resy", type=int)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--max-depth", type=int, default=17)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--integrator", default="path")
    ap.add_argument("--spp-per-pass", type=int, default=0)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--define", action="append", default=[], metavar="NAME=VALUE",
                    help="scene parameter, as mitsuba's -D (repeatable)")
    ap.add_argument("--as-published", action="store_true",
                    help="pass the scene only the --define parameters and render its own integrator: Mitsuba 3 "
                         "refuses parameters a scene does not use, and a published scene declares its own")
    a = ap.parse_args(argv)

    if a.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM_DEFAULT):
        os.environ["DRJIT_LIBLLVM_PATH"] = LLVM_DEFAULT

    t0 = time.perf_counter()
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant(a.variant)
    if a.threads > 0:
        dr.set_thread_count(a.threads)
    t_import = time.perf_counter() - t0

    params = dict(d.split("=", 1) for d in a.define)
    if not a.as_published:
        params |= {"spp": a.spp, "max_depth": a.max_depth, "integrator": a.integrator}
        if a.resx:
            params["resx"] = a.resx
        if a.resy:
            params["resy"] = a.resy
    t1 = time.perf_counter()
    scene = mi.load_file(a.scene, **params)
    t_load = time.perf_counter() - t1

    integrator = None
    if a.spp_per_pass > 0 and a.spp > a.spp_per_pass:
        integrator = mi.load_dict({"type": a.integrator, "max_depth": a.max_depth,
                                   "samples_per_pass": a.spp_per_pass})

    t2 = time.perf_counter()
    img = mi.render(scene, integrator=integrator, spp=int(a.spp), seed=int(a.seed))
    dr.eval(img)
    dr.sync_thread()
    arr = np.array(img, dtype=np.float32)
    t_render = time.perf_counter() - t2

    if arr.ndim == 3 and arr.shape[2] > 3:
        arr = arr[..., :3]
    h, w = arr.shape[:2]
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    if a.threads == 1:
        # Bitmap.write hangs (idle, forever) when Dr.Jit's pool was set to one thread (Mitsuba 3.9.1,
        # llvm_ad_rgb): the render is timed already, so the pool gets its default size back first.
        dr.set_thread_count(os.cpu_count() or 2)
    mi.Bitmap(np.ascontiguousarray(arr), mi.Bitmap.PixelFormat.RGB).write(a.out)

    ru = resource.getrusage(resource.RUSAGE_SELF)
    stats = {
        "renderer": "mitsuba3",
        "mitsuba_version": mi.__version__,
        "variant": a.variant,
        "integrator": "the scene's" if a.as_published else a.integrator,
        "scene": os.path.abspath(a.scene),
        "width": w,
        "height": h,
        "spp": a.spp,
        "spp_per_pass": a.spp_per_pass if integrator is not None else a.spp,
        "max_depth": a.max_depth,
        "seed": a.seed,
        "threads": a.threads or os.cpu_count(),
        "import_time_s": t_import,
        "load_time_s": t_load,
        "render_time_s": t_render,  # includes JIT compilation for llvm variants
        "samples_per_s": w * h * a.spp / t_render if t_render > 0 else None,
        "peak_memory_mb": _peak_memory_mb(ru),
        "cpu_time_s": ru.ru_utime + ru.ru_stime,
    }
    tmp = a.json + ".tmp"
    with open(tmp, "w") as f:
        json.dump(stats, f, indent=2)
    os.replace(tmp, a.json)
    return 0


if __name__ == "__main__":
    try:
        rc = main()
    except SystemExit as e:
        rc = e.code if isinstance(e.code, int) else 1
    except BaseException:
        traceback.print_exc()
        rc = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(rc)
