"""What `neepp view` shows, and the thread that renders it.

One session per server, shared by every page open on it: the camera, the integrator and its options.
Each change (a camera move, an option) cancels the render under way at once (LiveRender.cancel) and a
thread of the session's own renders the new view: first a coarse image (a quarter of the resolution, one
sample per pixel), then the full image, sent after each pass (a few times a second) as it converges, up to
the most samples per pixel a view gets. The integrator is kept across camera moves, so NEE++'s visibility
map, which belongs to the scene and not to the view, keeps learning from every view; a new integrator or
new options start it afresh.
"""
from __future__ import annotations

import json
import threading
import time
from pathlib import Path
from typing import Callable, Optional

import numpy as np

import neepp
from neepp import _neepp

from .orbit import OrbitCamera

PREVIEW_SCALE = 4


class Frame:
    """An image of one view, and what made it."""

    def __init__(self, view: int, image: np.ndarray, stats: dict):
        self.view, self.image, self.stats = view, image, stats


class ViewSession:
    def __init__(self, scene: neepp.Scene, integrator: str, options: dict, max_spp: int, threads: int = 0,
                 seed: Optional[int] = None, sampler: str = "", output_dir: Path = Path("neepp-view"),
                 display_interval: float = 0.1, preview: bool = True):
        self.scene = scene
        self.integrator = integrator or scene.integrator
        self.base_options = dict(options)  # the command line's -I, under what the page switches
        self.page_options: dict = {}
        self.max_spp = max_spp
        self.output_dir = Path(output_dir)
        self.display_interval = display_interval
        self.preview = preview
        cam = scene.camera
        self.camera = OrbitCamera(cam["to_world"], cam["fov"], scene.bounds)
        self.live = _neepp.LiveRender(scene, self.integrator, self.base_options, threads, sampler,
                                      scene.seed if seed is None else seed)
        self._cond = threading.Condition()
        self._generation = 0  # bumped by every change: the thread renders the newest
        self._pending_options: Optional[tuple] = None
        self._stopping = False
        self.latest: Optional[Frame] = None  # the newest full-resolution image, for save
        # Called from the render thread: with each frame, and with each message for every page.
        self.on_frame: Callable[[Frame], None] = lambda frame: None
        self.on_message: Callable[[dict], None] = lambda msg: None
        self._thread = threading.Thread(target=self._run, name="neepp-view-render", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self, timeout: float = 10.0) -> None:
        """Ends the render under way and the thread."""
        with self._cond:
            self._stopping = True
            self.live.cancel()
            self._cond.notify_all()
        if self._thread.is_alive():
            self._thread.join(timeout)

    def options(self) -> dict:
        return {**self.base_options, **self.page_options}

    def state(self) -> dict:
        """What a page shows besides the image: the scene, the integrator, its options, the camera, and
        what there is to choose from."""
        return {"type": "state", "scene": self.scene.path, "width": self.scene.width, "height": self.scene.height,
                "integrator": self.integrator, "options": self.options(),
                "scene_options": self.scene.integrator_options, "fov": self.camera.fov,
                "max_spp": self.max_spp, "catalog": _neepp.catalog()}

    # Changes, from the server's thread: each restarts the render.
    def camera_command(self, command: dict) -> None:
        args = {k: v for k, v in command.items() if k != "type"}
        self._change(lambda: getattr(self.camera, command["type"])(**args))

    def set_options(self, integrator: str, options: dict) -> None:
        """The integrator and the options the page sets (over the command line's); checked by the render
        thread, which keeps the old ones and says why when they are refused."""
        def apply():
            self._pending_options = (integrator, dict(options))
        self._change(apply)

    def _change(self, apply: Callable[[], None]) -> None:
        with self._cond:
            apply()
            self._generation += 1
            self.live.cancel()
            self._cond.notify_all()

    # The render thread.
    def _run(self) -> None:
        rendered = -1
        while True:
            with self._cond:
                while not self._stopping and self._generation == rendered:
                    self._cond.wait()
                if self._stopping:
                    return
                view, pending = self._generation, self._pending_options
                self._pending_options = None
                to_world, fov = self.camera.to_world(), self.camera.fov
                self.live.clear_cancel()  # under the lock: a change after this cancels what follows
            rendered = view
            try:
                if pending is not None:
                    self._switch(*pending)
                self.live.set_camera(to_world, fov)
                camera = {"to_world": to_world, "fov": fov}
                if self.preview and self._current(view):
                    self.live.render(1, PREVIEW_SCALE, 1.0, lambda im, info: self._frame(view, camera, im, info, True))
                if self._current(view):
                    self.live.render(self.max_spp, 1, self.display_interval,
                                     lambda im, info: self._frame(view, camera, im, info, False))
            except Exception as e:  # a render the integrator refuses (bdpt on a thin lens...): said, not fatal
                self.on_message({"type": "error", "message": str(e)})

    def _current(self, view: int) -> bool:
        with self._cond:
            return self._generation == view and not self._stopping

    def _switch(self, integrator: str, page_options: dict) -> None:
        options = {**self.base_options, **page_options}
        try:
            self.live.set_integrator(integrator, options)
        except ValueError as e:  # the page's choice is refused: it is told why, and shown what still holds
            self.on_message({"type": "error", "message": str(e)})
            self.on_message(self.state())
            return
        self.integrator, self.page_options = integrator, page_options
        self.on_message(self.state())

    def _frame(self, view: int, camera: dict, image: np.ndarray, info: dict, coarse: bool) -> None:
        if not self._current(view):  # a cancelled render's last image: of a view no longer shown
            return
        t = info["render_time_s"]
        stats = {**info, "view": view, "coarse": coarse, "integrator": self.integrator, "options": self.options(),
                 "samples_per_s": info["spp"] * info["width"] * info["height"] / t if t > 0 else 0.0, **camera}
        frame = Frame(view, image, stats)
        if not coarse:
            self.latest = frame
        self.on_frame(frame)

    def save(self, exposure: float = 0.0) -> list[str]:
        """Writes the newest full image as NNN.exr, NNN.png (at the page's exposure, in stops) and NNN.json
        (its statistics, the camera and the options) in the output folder; returns the paths."""
        frame = self.latest
        if frame is None:
            raise RuntimeError("no image to save yet")
        self.output_dir.mkdir(parents=True, exist_ok=True)
        n = 1
        while (self.output_dir / f"view_{n:03d}.exr").exists():
            n += 1
        base = self.output_dir / f"view_{n:03d}"
        neepp.write_exr(base.with_suffix(".exr"), frame.image)
        neepp.write_png(base.with_suffix(".png"), frame.image, exposure=2.0 ** exposure)
        record = {**frame.stats, "scene": self.scene.path, "exposure": exposure,
                  "saved_at": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
        base.with_suffix(".json").write_text(json.dumps(record, indent=2) + "\n")
        return [str(base.with_suffix(s)) for s in (".exr", ".png", ".json")]
