"""neepp: a physically based renderer with Next Event Estimation++.

    import neepp
    scene = neepp.load("scene.xml", resx=256, resy=256)
    image, stats = neepp.render(scene, spp=64, integrator="path", shadow_rays="neepp-adaptive")
    neepp.write_exr("out.exr", image)

`render` returns the image as an (H, W, 3) float32 numpy array and the statistics the CLI writes with
--stats, as a dict. Integrator options are keyword arguments (the CLI's -I key=value); scene parameters
are keyword arguments of `load` (the CLI's -D name=value). Errors are exceptions with the CLI's messages:
a scene problem is `SceneError` (a ValueError with file, line and problem), a bad option ValueError.
"""
from __future__ import annotations

import atexit
import json
from typing import Callable, Optional, Union

import numpy as np

from . import metrics
from . import _neepp
from ._neepp import Scene, SceneError, VisibilityMap

# A render still running on a daemon thread when the interpreter exits would be killed mid-render at its
# next GIL acquisition, its worker threads left running into the process's teardown (a crash at exit).
# Before finalization every render under way is cancelled (its thread gets the image so far) and waited for.
atexit.register(_neepp._stop_renders, 30.0)

__all__ = ["Scene", "SceneError", "VisibilityMap", "load", "check", "render", "read_image", "read_exr", "write_exr",
           "write_png", "metrics", "option_text"]


def option_text(value) -> str:
    """An option or parameter value as the scene file and the CLI spell it (True -> "true")."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ",".join(option_text(v) for v in value)
    return str(value)


def load(path, **parameters) -> Scene:
    """Loads a Mitsuba 3 XML scene. Keyword arguments override its <default> parameters, as -D does:
    ``neepp.load("scene.xml", resx=128, max_depth=8)``. Raises SceneError naming the file, line and
    problem."""
    return _neepp.load(str(path), {k: option_text(v) for k, v in parameters.items()})


def check(path, **parameters) -> list:
    """Every problem of a scene at once, without rendering it (as `neepp check`): unsupported plugins,
    missing files, properties nothing reads. A list of dicts with file, line, severity ("error": render
    would stop there; "warning") and problem; empty for a scene neepp renders as written."""
    return _neepp.check(str(path), {k: option_text(v) for k, v in parameters.items()})


def render(scene: Scene, spp: Optional[int] = None, time: Optional[float] = None, integrator: Optional[str] = None,
           seed: Optional[int] = None, threads: Optional[int] = None, sampler: Optional[str] = None,
           progress: Union[None, bool, Callable[[float], None]] = None, **options):
    """Renders a scene; returns ``(image, stats)``: an (H, W, 3) float32 array and the statistics dict.

    spp: samples per pixel (default: the scene's), or time: seconds to render for (not both).
    integrator: path, bdpt, light or pssmlt (default: the scene's); options: its options, as -I key=value
    (``shadow_rays="neepp-adaptive"``, ``max_depth=8``, ``light_sampler="visibility"``...).
    seed: the sampler's seed (default: the scene's). threads: worker threads (default: all cores).
    progress: a callable given the fraction done (0..1) a few times a second, or True for the CLI's bar.
    Ctrl-C stops the render and returns the image of the passes completed (stats["stopped_by"] is
    "cancel"), as the CLI does, and so does the callback returning False (None goes on); an exception
    raised by the callback stops it and propagates. The callback runs on the calling thread.

    Renders may run on several Python threads at once (the GIL is released while one works), each on
    its own `threads`, and give the images they give alone (README: "Threads").
    """
    if spp is not None and time is not None:
        raise ValueError("give spp or time, not both")
    if spp is not None and spp < 1:
        raise ValueError(f"spp must be at least 1, got {spp}")
    if time is not None and not time > 0:
        raise ValueError(f"time must be positive, got {time}")
    if threads is not None and threads < 1:
        raise ValueError(f"threads must be at least 1, got {threads}")
    image, stats = _neepp.render(scene, integrator or "", {k: option_text(v) for k, v in options.items()}, spp or 0,
                           float(time or 0), scene.seed if seed is None else int(seed), threads or 0, sampler or "",
                           progress)
    return image, json.loads(stats)


def read_image(path) -> np.ndarray:
    """Reads an image (OpenEXR, PNG, JPEG, HDR...) as an (H, W, C) float32 array: EXR linear, 8-bit files
    sRGB-encoded in [0, 1]. Raises RuntimeError naming the file."""
    return _neepp.read_image(str(path))


def read_exr(path) -> np.ndarray:
    """Reads an OpenEXR image as an (H, W, C) float32 array."""
    return read_image(path)


def write_exr(path, image, half: bool = False) -> None:
    """Writes an (H, W[, C]) image (C = 1, 3 or 4) to OpenEXR, float or half, replacing the file atomically."""
    _neepp.write_exr(str(path), np.ascontiguousarray(image, dtype=np.float32), half)


def write_png(path, image, exposure: float = 1.0) -> None:
    """Writes a linear image as an 8-bit sRGB PNG, scaled by exposure and clamped."""
    _neepp.write_png(str(path), np.ascontiguousarray(image, dtype=np.float32), exposure)
