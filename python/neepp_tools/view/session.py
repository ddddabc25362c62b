"""What `neepp view` shows, and the thread that renders it.

One session per server, shared by every page open on it: the camera, the integrator and its options.
Each change (a camera move, an option) cancels the render under way at once (LiveRender.cancel) and a
thread of the session's own renders the new view: first a coarse image (a quarter of the resolution, one
sample per pixel), then the full image, sent after each pass (a few times a second) as it converges, up to
the most samples per pixel a view gets. Within a pass the image is sent too (the completed passes with the
tiles of the running pass that are finished), so that it moves on about ten times a second however long a
pass of the scene takes; within the first pass, whose unfinished tiles have no sample yet, the finished
tiles are shown over the coarse image (stats["composed"]). The integrator is kept across camera moves, so
NEE++'s visibility map, which belongs to the scene and not to the view, keeps learning from every view; a
new integrator or new options start it afresh.

What the integrator learned is read by the render thread alone, between passes (from the callback of a
frame between passes, not of one within a pass) or between renders: a page's question about the map (a
clicked point) is queued for it and answered through a future, so that no pass ever runs while the map is
read.
"""
from __future__ import annotations

import concurrent.futures
import json
import threading
import time
from pathlib import Path
from typing import Callable, Optional

import numpy as np

import neepp
from neepp import _neepp

from ..metrics import relmse
from .orbit import OrbitCamera

PREVIEW_SCALE = 4
# The lights the map view lists for a clicked point: the most probable under its light choice.
TOP_LIGHTS = 8


class Frame:
    """An image of one view, and what made it."""

    def __init__(self, view: int, image: np.ndarray, stats: dict):
        self.view, self.image, self.stats = view, image, stats


class ViewSession:
    def __init__(self, scene: neepp.Scene, integrator: str, options: dict, max_spp: int, threads: int = 0,
                 seed: Optional[int] = None, sampler: str = "", output_dir: Path = Path("neepp-view"),
                 display_interval: float = 0.1, preview: bool = True):
        self.scene = scene
        # The film's size, read once: while the coarse image renders, the scene's camera has a quarter of it,
        # and a page that connects then must still be told the image's size.
        self.width, self.height = scene.width, scene.height
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
        self._requests: list = []  # (function, future): questions for the render thread
        self._cells: Optional[tuple] = None  # (camera, pixel_cells()) of the last map view
        self._seen_count = 0
        # The image the relMSE is measured against ((H, W, 3) float32) and what it is; None: no reference.
        self.reference: Optional[np.ndarray] = None
        self.reference_name = ""
        self.last_saved: Optional[Frame] = None
        self._stopping = False
        self.latest: Optional[Frame] = None  # the newest full-resolution image, for save
        self._coarse: Optional[Frame] = None  # the coarse image of the view in render, under its first pass
        self.view_in_render, self.camera_in_render = -1, {"to_world": self.camera.to_world(), "fov": self.camera.fov}
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
        with self._cond:
            requests, self._requests = self._requests, []
        for _, future in requests:
            future.set_exception(RuntimeError("neepp view stopped"))

    def options(self) -> dict:
        return {**self.base_options, **self.page_options}

    def state(self) -> dict:
        """What a page shows besides the image: the scene, the integrator, its options, the camera, and
        what there is to choose from."""
        return {"type": "state", "scene": self.scene.path, "width": self.width, "height": self.height,
                "integrator": self.integrator, "options": self.options(),
                "scene_options": self.scene.integrator_options, "fov": self.camera.fov,
                "max_spp": self.max_spp, "catalog": _neepp.catalog(), "reference": self.reference_name or None}

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

    def set_reference(self, image: Optional[np.ndarray], name: str) -> None:
        """The image the relMSE is measured against (the scene's film size, RGB or RGBA), or None. Only
        camera moves and options make another image: the relMSE means something for the view the reference
        was made of (the scene's camera, or the saved image's)."""
        if image is None:
            self.reference, self.reference_name = None, ""
            return
        image = np.asarray(image, dtype=np.float32)
        if image.ndim != 3 or image.shape[2] < 3 or image.shape[:2] != (self.height, self.width):
            raise ValueError(f"the reference {name} is {'x'.join(map(str, image.shape[1::-1]))}, the image "
                             f"{self.width}x{self.height}")
        if not np.all(np.isfinite(image[..., :3])):
            raise ValueError(f"the reference {name} has pixels that are not finite")
        self.reference, self.reference_name = np.ascontiguousarray(image[..., :3]), name

    def reference_from_saved(self) -> None:
        """The last image saved becomes the reference (a difference against a stored image)."""
        if self.last_saved is None:
            raise ValueError("no image saved yet")
        self.set_reference(self.last_saved.image, f"view {self.last_saved.view} as saved")

    def map_view(self, x: int, y: int) -> concurrent.futures.Future:
        """The map seen from pixel (x, y) of the full image, as a future (answered by the render thread
        between passes; the image is not restarted): a dict (the clicked point, its cell, the cells its row
        knows, the light distribution there) and the heat map (_seen_visibility) as a (height, width)
        float32 array, NaN where the map knows nothing or the pixel sees nothing; None without a map."""
        return self._ask(lambda: self._map_view(x, y))

    def _ask(self, function: Callable) -> concurrent.futures.Future:
        future: concurrent.futures.Future = concurrent.futures.Future()
        with self._cond:
            if self._stopping:
                future.set_exception(RuntimeError("neepp view stopped"))
            else:
                self._requests.append((function, future))
                self._cond.notify_all()
        return future

    def _answer_requests(self) -> None:
        """Runs the queued questions (render thread: between passes or renders)."""
        with self._cond:
            requests, self._requests = self._requests, []
        for function, future in requests:
            try:
                future.set_result(function())
            except Exception as e:  # noqa: BLE001 - said to the page that asked, never fatal here
                future.set_exception(e)

    def _map_view(self, x: int, y: int):
        if not (0 <= x < self.width and 0 <= y < self.height):
            raise ValueError(f"pixel ({x}, {y}) is outside the {self.width}x{self.height} image")
        camera = {"to_world": self.camera_in_render["to_world"], "fov": self.camera_in_render["fov"]}
        result = {"type": "map", "view": self.view_in_render, "x": x, "y": y, "integrator": self.integrator,
                  "options": self.options(), **camera}
        info = self.live.map_info()
        hit = self.live.pick(x, y)
        result["map"] = info
        result["hit"] = hit is not None
        heat = None
        if hit is not None:
            result.update(point=list(hit["point"]), normal=list(hit["normal"]), cell=hit["cell"])
            pmf = hit["light_pmf"]
            if pmf is not None:
                lights = self.scene.lights
                order = np.argsort(-pmf, kind="stable")[:TOP_LIGHTS]
                result["light_sampler"] = hit["light_sampler"]
                result["light_count"] = len(lights)
                result["lights"] = [{"index": int(i), "pmf": float(pmf[i]), "type": lights[i]["type"],
                                     "center": list(lights[i]["center"]) if "center" in lights[i] else None}
                                    for i in order if pmf[i] > 0]
            if info is not None and hit["cell"] >= 0:
                key = json.dumps(camera)
                if self._cells is None or self._cells[0] != key:  # the first hits of this view, once
                    self._cells = (key, self.live.pixel_cells())
                cells = self._cells[1]
                heat = self._seen_visibility(hit["cell"], cells)
                result["seen_cells"] = self._seen_count
                known = np.isfinite(heat)
                result["known_fraction"] = float(known.mean())
                result["heat_mean"] = float(heat[known].mean()) if known.any() else None
        return result, heat

    def _seen_visibility(self, cell: int, cells: np.ndarray) -> np.ndarray:
        """The heat map of the map view: for each pixel, the mean of Ṽ from its first hit's cell to the
        clicked cell and to the cells the clicked cell sees (those its row of the map knows: for NEE++
        under a path tracer, the cells of the light points its shadow rays went to), over the pairs the map
        knows; NaN where it knows none. Clicked on a wall: where the light it sees is visible from, as the
        map has it (that light's shadows); clicked on a light: Ṽ from each pixel to it. (Ṽ between a
        wall's cell and each pixel's own cell alone would be unknown almost everywhere: NEE++ learns pairs
        of a shading cell and a light cell only.)"""
        row = self.live.visibility_row(cell)
        seen = np.flatnonzero(np.isfinite(row))
        self._seen_count = int(seen.size)
        seen = np.union1d(seen, [cell])
        total = np.zeros(row.shape, np.float64)
        count = np.zeros(row.shape, np.int64)
        for b in seen:
            r = self.live.visibility_row(int(b))
            known = np.isfinite(r)
            total[known] += r[known]
            count[known] += 1
        per_cell = np.full(row.shape, np.nan, np.float32)
        per_cell[count > 0] = total[count > 0] / count[count > 0]
        return np.where(cells >= 0, per_cell[np.maximum(cells, 0)], np.float32(np.nan)).astype(np.float32)

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
                while not self._stopping and self._generation == rendered and not self._requests:
                    self._cond.wait()
                if self._stopping:
                    return
                questions_only = self._generation == rendered
            if questions_only:  # the view is done: answered here, without rendering again
                self._answer_requests()
                continue
            with self._cond:
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
                self.view_in_render, self.camera_in_render = view, camera  # what the map view sees
                if self.preview and self._current(view):
                    self.live.render(1, PREVIEW_SCALE, 1.0, lambda im, info: self._frame(view, camera, im, info, True))
                if self._current(view):
                    # The first pass under way too, where its finished tiles can go over a coarse image.
                    self.live.render(self.max_spp, 1, self.display_interval,
                                     lambda im, info: self._frame(view, camera, im, info, False), self.preview)
            except Exception as e:  # a render the integrator refuses (bdpt on a thin lens...): said, not fatal
                self.on_message({"type": "error", "message": str(e)})
            self._answer_requests()

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
        if not info["within_pass"]:
            self._answer_requests()  # between passes: the map holds still (within one it is learning)
        if not self._current(view):  # a cancelled render's last image: of a view no longer shown
            return
        composed = not coarse and info["within_pass"] and info["spp"] == 0
        if composed:  # the first pass under way: its unfinished tiles (NaN) show the coarse image
            if self._coarse is None or self._coarse.view != view:
                return
            image = over_coarse(image, self._coarse.image)
        t = info["render_time_s"]
        # Within a pass the tiles it finished have more samples than the others: spp is the fewest a pixel
        # has, spp_max the most, spp_mean their mean (the samples in the image).
        stats = {**info, "view": view, "coarse": coarse, "composed": composed, "integrator": self.integrator,
                 "options": self.options(),
                 "samples_per_s": info["spp_mean"] * info["width"] * info["height"] / t if t > 0 else 0.0, **camera}
        reference = self.reference
        if not coarse and reference is not None and reference.shape == image.shape:
            # neepp compare's relMSE (metrics.relmse: squared error over reference² + 0.01, averaged).
            stats["relmse"] = relmse(image, reference)
            stats["reference"] = self.reference_name
        frame = Frame(view, image, stats)
        if coarse:
            self._coarse = frame
        elif not composed:  # save writes a rendered image, not one partly the coarse image
            self.latest = frame
        self.on_frame(frame)

    def save(self, exposure: float = 0.0, timeout: float = 60.0) -> list[str]:
        """Writes the newest full image as view_NNN.exr, view_NNN.png (at the page's exposure, in stops),
        NEE++'s visibility map as view_NNN.vis (the project's map file, which -I visibility_map=FILE and
        neepp.VisibilityMap.load read; where the integrator keeps a map) and view_NNN.json (the image's
        statistics, the camera, the options and the map's size) in the output folder; returns the paths.
        Called off the render thread: the map is written by the render thread, between passes."""
        frame = self.latest
        if frame is None:
            raise RuntimeError("no image to save yet")
        self.output_dir.mkdir(parents=True, exist_ok=True)
        n = 1
        while any((self.output_dir / f"view_{n:03d}{s}").exists() for s in (".exr", ".json")):
            n += 1
        base = self.output_dir / f"view_{n:03d}"
        map_path = base.with_suffix(".vis")

        def save_map():
            info = self.live.map_info()
            return info if info is not None and self.live.save_visibility_map(map_path) else None

        map_info = self._ask(save_map).result(timeout)
        neepp.write_exr(base.with_suffix(".exr"), frame.image)
        neepp.write_png(base.with_suffix(".png"), frame.image, exposure=2.0 ** exposure)
        record = {**frame.stats, "scene": self.scene.path, "exposure": exposure,
                  "saved_at": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
        if map_info is not None:
            # The map as saved: it may have learned a pass or two past the image's statistics.
            record["visibility_map"] = {"file": map_path.name, **map_info}
        base.with_suffix(".json").write_text(json.dumps(record, indent=2) + "\n")
        self.last_saved = frame
        suffixes = (".exr", ".png", ".json") + ((".vis",) if map_info is not None else ())
        return [str(base.with_suffix(s)) for s in suffixes]


def over_coarse(image: np.ndarray, coarse: np.ndarray) -> np.ndarray:
    """A frame within the first pass ((H, W, 3), NaN in the pixels of its unfinished tiles) with those pixels
    taken from the coarse image of the view, enlarged: each from the coarse pixel its centre falls in (both
    images span the same field of view)."""
    missing = np.isnan(image[..., 0])
    ys, xs = np.nonzero(missing)
    height, width = missing.shape
    out = image if image.flags.writeable else image.copy()
    out[ys, xs] = coarse[(2 * ys + 1) * coarse.shape[0] // (2 * height), (2 * xs + 1) * coarse.shape[1] // (2 * width)]
    return out
