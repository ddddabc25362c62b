"""`neepp view` as a user runs it, on door-ajar at a tiny resolution: the server listens on loopback only and
serves a page that needs no network; its websocket delivers frames that converge, a camera move restarts
the image, an option change changes the statistics, save writes the files, malformed messages are refused
without harm, two pages share the view; the page runs its own self-test in a real headless Chromium; and
SIGTERM stops it cleanly, freeing the port. Also the viewer's camera and the renderer under it
(neepp._neepp.LiveRender), which keeps the integrator, and with it NEE++'s map, across camera moves."""
from __future__ import annotations

import asyncio
import json
import math
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

aiohttp = pytest.importorskip("aiohttp", reason="aiohttp is not installed (scripts/setup_python.sh installs it)")
neepp = pytest.importorskip("neepp", reason="the neepp package is not installed (scripts/test.sh installs it)")

from neepp_tools.view import messages  # noqa: E402
from neepp_tools.view.orbit import OrbitCamera  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
DEMO = REPO / "scenes" / "door-ajar" / "scene.xml"
W, H = 48, 27
TIMEOUT = 30.0


def start_view(neepp_bin, out_dir, *extra):
    """A `neepp view` of the demo at W x H and the URL it printed."""
    proc = subprocess.Popen([str(neepp_bin), "view", str(DEMO), "-D", f"resx={W}", "-D", f"resy={H}", "--threads", "1",
                             "--spp", "100000", "-o", str(out_dir), *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    m = re.search(r"(http://127\.0\.0\.1:(\d+)/)", line)
    if not m:
        proc.kill()
        pytest.fail(f"neepp view printed no address: {line!r} {proc.stderr.read()[-2000:]}")
    return proc, m.group(1), int(m.group(2))


@pytest.fixture(scope="module")
def viewer(neepp_bin, tmp_path_factory):
    out = tmp_path_factory.mktemp("view")
    # A reference of the film's size (not the scene's image: the relMSE need only be measured against it).
    reference = np.full((H, W, 3), 0.05, np.float32)
    reference[:, : W // 2] = 0.2
    neepp.write_exr(out / "reference.exr", reference)
    proc, url, port = start_view(neepp_bin, out / "saved", "--reference", str(out / "reference.exr"))
    yield {"proc": proc, "url": url, "port": port, "out": out / "saved", "reference": reference}
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=20)


class Page:
    """A websocket client that reads as the page does: the state, errors, saves and decoded frames."""

    def __init__(self, ws):
        self.ws = ws
        self.state = None

    async def next(self, timeout=TIMEOUT):
        return await self._decode(await self.ws.receive(timeout=timeout))

    async def _decode(self, msg):
        if msg.type == aiohttp.WSMsgType.BINARY:
            header, pixels = messages.decode_frame(msg.data)
            if header.get("kind"):  # a map view or the reference, not a frame
                return {"type": "binary", "header": header, "pixels": pixels}
            image = np.frombuffer(pixels, dtype="<f4").reshape(header["height"], header["width"], 3)
            return {"type": "frame", **header, "image": image}
        if msg.type == aiohttp.WSMsgType.TEXT:
            m = json.loads(msg.data)
            if m["type"] == "state":
                self.state = m
            return m
        return {"type": "closed", "ws_type": str(msg.type)}

    async def until(self, test, what, timeout=TIMEOUT):
        """The first message for which test holds (messages before it are passed over)."""
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"timed out waiting for {what}")
            m = await self.next(left)
            if test(m):
                return m
            assert m["type"] != "closed", f"the server closed the websocket while waiting for {what}: {m}"

    async def send(self, msg):
        await self.ws.send_str(msg if isinstance(msg, str) else json.dumps(msg))


def full_frame(view=None):
    return lambda m: m["type"] == "frame" and not m["coarse"] and (view is None or m["view"] == view)


async def with_page(url, body):
    async with aiohttp.ClientSession() as http:
        async with http.ws_connect(url + "ws") as ws:
            return await body(Page(ws))


def run(coro):
    return asyncio.run(coro)


# The camera and the renderer under the server (before the server starts: it would share the cores).

def test_live_render_keeps_its_integrator_across_camera_moves():
    scene = neepp.load(DEMO, resx=32, resy=18)
    live = neepp._neepp.LiveRender(scene, "path", {"shadow_rays": "neepp"}, 2, "", 0)
    merged = lambda stats: stats["integrator_statistics"]["shadow_rays"]["roulette"]["passes_merged"]  # noqa: E731
    first = json.loads(live.render(8))
    assert live.prepared and merged(first) == first["passes"]
    cam = OrbitCamera(scene.camera["to_world"], scene.camera["fov"], scene.bounds)
    cam.orbit(0.3, 0.0)
    live.set_camera(cam.to_world(), cam.fov)
    frames = []
    second = json.loads(live.render(8, on_frame=lambda image, info: frames.append((image.shape, info))))
    assert merged(second) == first["passes"] + second["passes"]  # the map went on learning
    assert frames[-1][1]["final"] and frames[-1][1]["spp"] == 8 and frames[-1][0] == (18, 32, 3)
    coarse = []
    live.render(1, scale=4, on_frame=lambda image, info: coarse.append(image.shape))
    assert coarse == [(5, 8, 3)] and scene.width == 32  # the film is back to its size
    live.set_integrator("path", {"shadow_rays": "neepp"})  # new options: a new integrator, prepared anew
    assert not live.prepared
    with pytest.raises(ValueError, match="rotation"):
        live.set_camera([[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], 40)
    with pytest.raises(ValueError, match="fov"):
        live.set_camera(cam.to_world(), 200)
    assert scene.camera["fov"] == pytest.approx(cam.fov)  # a refused camera leaves the one in force


def test_live_render_map_view_reads_the_map(tmp_path):
    """The map view's parts: a pixel's first hit and its cell, the map's row of that cell (Ṽ to every cell,
    NaN where unknown) equal to the map's counts as its file holds them, and the light distribution there."""
    scene = neepp.load(DEMO, resx=32, resy=18)
    live = neepp._neepp.LiveRender(scene, "path", {"shadow_rays": "neepp"}, 2, "", 0)
    assert live.map_info() is None  # no map before the first render prepares it
    live.render(4)
    info = live.map_info()
    assert info["resolution"] == 16 and info["known_pairs"] > 0
    cells = live.pixel_cells()
    assert cells.shape == (18, 32) and cells.dtype == np.int32
    assert np.all((cells >= -1) & (cells < info["voxel_count"])) and np.count_nonzero(cells >= 0) > 0.9 * cells.size
    # A pixel whose cell the map knows pairs of (NEE++ learns pairs of a shading cell and a light cell).
    y, x = next((y, x) for y, x in np.argwhere(cells >= 0) if np.isfinite(live.visibility_row(cells[y, x])).any())
    hit = live.pick(int(x), int(y))
    assert hit["cell"] == cells[y, x] and len(hit["point"]) == 3
    assert hit["light_pmf"].shape == (len(scene.lights),) and hit["light_pmf"].sum() == pytest.approx(1.0)
    row = live.visibility_row(hit["cell"])
    assert row.shape == (info["cell_count"],)
    # The row against the map itself, read back from the file it saves (the project's map format).
    assert live.save_visibility_map(tmp_path / "map.vis")
    saved = neepp.VisibilityMap.load(tmp_path / "map.vis", scene, 16)
    counts = saved.counts()
    pairs = np.array([saved.pair_index(hit["cell"], b) for b in range(info["cell_count"])])
    visible, traced = counts[pairs, 0].astype(np.float64), counts[pairs, 1].astype(np.float64)
    expect = np.where(traced > 0, (visible + 1) / (traced + 2), np.nan)
    assert np.array_equal(np.isnan(row), np.isnan(expect))
    assert np.allclose(row[traced > 0], expect[traced > 0], rtol=1e-6)
    assert np.count_nonzero(traced > 0) > 0
    # The page's heat map (ViewSession's, from the render thread, here called directly between renders): per
    # pixel, the mean of Ṽ from its cell to the clicked cell and to the cells the clicked cell sees, over
    # the pairs the map knows, as the file gives them.
    from neepp_tools.view.session import ViewSession
    session = ViewSession(neepp.load(DEMO, resx=32, resy=18), "path", {"shadow_rays": "neepp"}, max_spp=4, threads=2)
    session.live.render(4)
    result, heat = session._map_view(int(x), int(y))
    assert session.live.save_visibility_map(tmp_path / "session.vis")
    saved = neepp.VisibilityMap.load(tmp_path / "session.vis", scene, 16)
    counts = saved.counts()

    def estimates(a):
        pairs = np.array([saved.pair_index(a, b) for b in range(info["cell_count"])])
        v, t = counts[pairs, 0].astype(np.float64), counts[pairs, 1].astype(np.float64)
        return np.where(t > 0, (v + 1) / (t + 2), np.nan)

    clicked = estimates(result["cell"])
    targets = sorted(set(np.flatnonzero(np.isfinite(clicked)).tolist()) | {result["cell"]})
    table = np.array([estimates(b) for b in targets])  # (targets, cells)
    known = np.isfinite(table).sum(axis=0)
    per_cell = np.full(table.shape[1], np.nan)
    per_cell[known > 0] = np.nansum(table, axis=0)[known > 0] / known[known > 0]
    expect = np.where(cells >= 0, per_cell[np.maximum(cells, 0)], np.nan)
    assert result["seen_cells"] == len(targets) - (0 if np.isfinite(clicked[result["cell"]]) else 1)
    assert np.array_equal(np.isnan(heat), np.isnan(expect)) and np.isfinite(heat).any()
    assert np.allclose(heat[np.isfinite(heat)], expect[np.isfinite(expect)], rtol=1e-5)
    with pytest.raises(IndexError):
        live.visibility_row(info["cell_count"])
    with pytest.raises(ValueError, match="outside"):
        live.pick(32, 0)
    # No map where the integrator keeps none (plain NEE, the bvh light sampler); a pick still answers.
    plain = neepp._neepp.LiveRender(neepp.load(DEMO, resx=32, resy=18), "path", {}, 2, "", 0)
    plain.render(1)
    assert plain.map_info() is None and plain.pick(13, 11)["cell"] == -1
    assert not plain.save_visibility_map(tmp_path / "none.vis") and not (tmp_path / "none.vis").exists()
    with pytest.raises(RuntimeError, match="no visibility map"):
        plain.pixel_cells()


def test_live_render_a_kept_map_makes_a_new_views_first_frames_cheaper():
    """The map kept across a camera move, against a fresh NEE++ render of the new view, over the first 4
    samples per pixel, at 6 seeds each (independent renders; the per-pixel variance across them). Equal
    samples cost the two different amounts: a fresh render seeds its map (camera paths and shadow rays) and
    traces every shadow ray of its first pass (the probe), while the kept map skips rays from the first
    pass. Their cost is counted in rays traced (camera paths, shadow rays, seeding), not in seconds, so the
    test does not depend on the machine's load. Per sample the two are about equally noisy (the fresh
    render's probe pass traces every shadow ray; the kept map skips some of them), per ray traced the kept
    map is far ahead, which is what a person moving the camera sees: the first frames of the new view
    arrive sooner. Deterministic: fixed seeds, and the renderer gives the same image on any thread count."""
    def render(live, spp):
        images = []
        stats = json.loads(live.render(spp, on_frame=lambda image, info: images.append(image) if info["final"] else None))
        return images[-1], stats

    kept, fresh, kept_rays, fresh_rays = [], [], 0, 0
    for seed in range(6):
        scene = neepp.load(DEMO, resx=48, resy=27)
        cam = OrbitCamera(scene.camera["to_world"], scene.camera["fov"], scene.bounds)
        cam.orbit(0.15, 0.03)
        live = neepp._neepp.LiveRender(scene, "path", {"shadow_rays": "neepp"}, 2, "", 100 + seed)
        live.render(32)  # the first view: the map learns
        live.set_camera(cam.to_world(), cam.fov)
        image, stats = render(live, 4)
        # The map carried over (it went on merging what the first view learned) and was not seeded again.
        assert stats["integrator_statistics"]["shadow_rays"]["roulette"]["passes_merged"] > stats["passes"]
        kept.append(image)
        kept_rays += stats["rays"] + stats["shadow_rays"]
        other = neepp._neepp.LiveRender(neepp.load(DEMO, resx=48, resy=27), "path", {"shadow_rays": "neepp"}, 2, "",
                                        200 + seed)
        other.set_camera(cam.to_world(), cam.fov)
        image, stats = render(other, 4)
        fresh.append(image)
        built = stats["integrator_statistics"]["shadow_rays"]["map"]
        fresh_rays += stats["rays"] + stats["shadow_rays"] + built["build_camera_rays"] + built["build_shadow_rays"]
    kept, fresh = np.array(kept), np.array(fresh)
    mean = np.concatenate([kept, fresh]).mean(axis=0)
    relvar = lambda images: float(np.mean(images.var(axis=0, ddof=1) / (mean ** 2 + 0.01)))  # noqa: E731
    per_sample = relvar(kept) / relvar(fresh)
    per_ray = per_sample * kept_rays / fresh_rays
    print(f"kept map / fresh: relative variance per sample {per_sample:.3f}, per ray {per_ray:.3f} "
          f"({kept_rays} / {fresh_rays} rays)")
    assert per_sample < 1.5, per_sample  # about equal: the kept map only rejects from its first pass
    assert per_ray < 0.5, (per_ray, kept_rays, fresh_rays)


def test_live_render_shows_a_pass_under_way():
    # A pass of one sample per pixel far longer than the display interval: frames come within it (the
    # tiles it finished over the completed passes), say so, and say how many samples their pixels have.
    scene = neepp.load(DEMO, resx=256, resy=144)
    live = neepp._neepp.LiveRender(scene, "path", {"shadow_rays": "nee"}, 1, "", 0)
    frames, refused = [], []

    def on_frame(image, info):
        frames.append(info)
        if info["within_pass"]:  # what the integrator learns is changing: the map view waits for a pass's end
            with pytest.raises(RuntimeError, match="on_frame"):
                live.map_info()
            refused.append(True)

    stats = json.loads(live.render(4, display_interval=0.01, on_frame=on_frame))
    assert stats["spp"] == 4 and stats["passes"] == 4  # passes of one sample per pixel
    within = [f for f in frames if f["within_pass"]]
    assert len(within) >= 3 and len(refused) == len(within)
    for f in within:
        assert f["spp"] < f["spp_mean"] <= f["spp_max"] == f["spp"] + 1 <= 4 and not f["final"]
    assert any(f["spp_mean"] < f["spp_max"] for f in within)  # part of a pass's tiles
    means = [f["spp_mean"] for f in frames]
    assert means == sorted(means)  # never an older image after a newer one
    # A pass shown under way is shown at its end too: where the map view may be asked.
    between = {f["spp"] for f in frames if not f["within_pass"] and not f["final"]}
    assert {f["spp"] + 1 for f in within} - {4} <= between, (within, between)
    assert frames[-1]["final"] and not frames[-1]["within_pass"] and frames[-1]["spp_mean"] == 4


def test_a_moved_views_first_pass_is_shown_over_its_coarse_image():
    """After a camera move the session shows the coarse image, then, before the first full-resolution pass is
    complete, frames of that pass's finished tiles over the coarse image (the render loop marks the pixels of
    the unfinished tiles NaN; the session fills them from the coarse image, enlarged): each 32-pixel tile is
    either the coarse image's pixels, exactly, or the pass's own, as the frame at the pass's end has them
    (inside the filter's reach of the tile's edge)."""
    from neepp_tools.view.session import ViewSession
    width, height, tile, margin = 256, 144, 32, 3
    session = ViewSession(neepp.load(DEMO, resx=width, resy=height), "path", {"shadow_rays": "nee"}, max_spp=2,
                          threads=1, display_interval=0.01)
    frames = []
    got = threading.Condition()

    def on_frame(frame):
        with got:
            frames.append(frame)
            got.notify_all()

    def final_of(view):
        with got:
            assert got.wait_for(lambda: any(f.view == view and f.stats["final"] and not f.stats["coarse"] for f in frames),
                                timeout=TIMEOUT)

    session.on_frame = on_frame
    session.start()
    try:
        final_of(0)
        session.camera_command({"type": "orbit", "dx": 0.1, "dy": 0.02})
        final_of(1)
    finally:
        session.stop()
    moved = [f for f in frames if f.view == 1]
    assert moved[0].stats["coarse"] and moved[0].image.shape == (math.ceil(height / 4), math.ceil(width / 4), 3)
    end = next(i for i, f in enumerate(moved) if not f.stats["coarse"] and not f.stats["within_pass"])
    assert moved[end].stats["spp"] == 1  # the first pass's end
    composed = [f for f in moved[1:end] if f.stats["composed"]]
    assert composed, [f.stats for f in moved[:end + 1]]
    assert all(f.stats["composed"] == (f.stats["spp"] == 0 and not f.stats["coarse"]) for f in moved)
    coarse = moved[0].image
    rows = (2 * np.arange(height) + 1) * coarse.shape[0] // (2 * height)
    cols = (2 * np.arange(width) + 1) * coarse.shape[1] // (2 * width)
    enlarged = coarse[rows][:, cols]
    first_pass = moved[end].image
    tiles = math.ceil(width / tile) * math.ceil(height / tile)
    partial = 0
    for f in composed:
        image = f.image
        assert image.shape == (height, width, 3) and np.all(np.isfinite(image))
        finished = area = 0
        for ty in range(0, height, tile):
            for tx in range(0, width, tile):
                block = (slice(ty, ty + tile), slice(tx, tx + tile))
                inner = (slice(ty + margin, ty + tile - margin), slice(tx + margin, tx + tile - margin))
                if np.array_equal(image[block], enlarged[block]):
                    continue
                assert np.array_equal(image[inner], first_pass[inner]), (tx, ty)
                finished += 1
                area += image[block].shape[0] * image[block].shape[1]
        assert finished > 0
        assert f.stats["spp_mean"] == pytest.approx(area / (width * height))
        partial += finished < tiles
    assert partial > 0


def test_live_render_cancel_stops_at_once():
    scene = neepp.load(DEMO, resx=64, resy=36)
    live = neepp._neepp.LiveRender(scene, "path", {}, 2, "", 0)
    seen = []

    def on_frame(image, info):
        seen.append(info["spp"])
        live.cancel()  # as the server does, from another thread, when the camera moves

    stats = json.loads(live.render(1_000_000, display_interval=0.0, on_frame=on_frame))
    assert stats["stopped_by"] == "cancel" and stats["spp"] < 1000
    live.clear_cancel()
    assert json.loads(live.render(2))["stopped_by"] == "spp"


def test_orbit_camera_moves():
    to_world = [[1, 0, 0, 0], [0, 1, 0, 1], [0, 0, 1, -5], [0, 0, 0, 1]]
    cam = OrbitCamera(to_world, 40.0, ((-1, -1, -1), (1, 1, 1)))
    assert np.allclose(cam.to_world(), to_world)  # the scene's own camera, as it was
    d = cam.distance
    cam.orbit(0.5, 0.3)
    assert cam.distance == pytest.approx(d) and not np.allclose(cam.to_world(), to_world)
    m = np.array(cam.to_world())
    assert np.allclose(m[:3, :3].T @ m[:3, :3], np.identity(3), atol=1e-9)  # still a rotation
    assert np.allclose(m[:3, 2], (cam.target - cam.position) / cam.distance)  # looking at the target
    cam.orbit(0.0, 100.0)  # never over the pole
    assert np.dot(np.array(cam.to_world())[:3, 1], [0, 1, 0]) > 0
    target = cam.target.copy()
    cam.pan(0.1, 0.0)
    assert not np.allclose(cam.target, target) and cam.distance == pytest.approx(d)
    cam.dolly(math.log(2))
    assert cam.distance == pytest.approx(d / 2)
    cam.zoom(10.0)
    assert cam.fov == 150.0
    cam.reset()
    assert np.allclose(cam.to_world(), to_world) and cam.fov == 40.0
    mirrored = [[-1, 0, 0, 0], [0, 1, 0, 1], [0, 0, 1, -5], [0, 0, 0, 1]]
    assert np.allclose(OrbitCamera(mirrored, 40.0, ((-1, -1, -1), (1, 1, 1))).to_world(), mirrored)


# The server, as a user runs it.

def test_listens_on_loopback_only(viewer):
    out = subprocess.run(["ss", "-ltnpH"], capture_output=True, text=True).stdout
    mine = [line.split() for line in out.splitlines() if f"pid={viewer['proc'].pid}," in line]
    assert mine, out
    for fields in mine:
        assert fields[3].startswith("127.0.0.1:"), fields
    assert any(fields[3] == f"127.0.0.1:{viewer['port']}" for fields in mine)


def test_page_needs_no_network_and_answers_its_own_host_only(viewer):
    async def body():
        async with aiohttp.ClientSession() as http:
            texts = {}
            for name in ("", "view.js", "view.css"):
                async with http.get(viewer["url"] + name) as r:
                    assert r.status == 200, name
                    assert "default-src 'self'" in r.headers["Content-Security-Policy"]
                    texts[name] = await r.text()
            # A page elsewhere reaching the port by another name (DNS rebinding) is refused.
            async with http.get(viewer["url"], headers={"Host": f"attacker.example:{viewer['port']}"}) as r:
                assert r.status == 403
            async with http.get(viewer["url"] + "../../etc/passwd") as r:
                assert r.status == 404
            return texts

    texts = run(body())
    for name, text in texts.items():
        assert not re.search(r"(https?:)?//[a-z0-9.-]+\.[a-z]{2,}", text, flags=re.I), name
    assert 'src="view.js"' in texts[""] and "ws://" in texts["view.js"]


def test_frames_converge_on_two_pages_at_once(viewer):
    async def body():
        async with aiohttp.ClientSession() as http:
            async with http.ws_connect(viewer["url"] + "ws") as a, http.ws_connect(viewer["url"] + "ws") as b:
                pa, pb = Page(a), Page(b)
                state = await pa.until(lambda m: m["type"] == "state", "the state")
                assert state["width"] == W and state["height"] == H and state["integrator"] == "path"
                names = [d["name"] for d in state["catalog"]["integrators"]]
                assert "path" in names and "bdpt" in names
                policies = [p[0] for p in state["catalog"]["shadow_ray_policies"]]
                assert {"nee", "neepp", "neepp-adaptive"} <= set(policies)
                first = await pa.until(full_frame(), "a full frame")
                later = [await pa.until(full_frame(first["view"]), "more frames") for _ in range(3)]
                other = await pb.until(full_frame(first["view"]), "a frame on the second page")
                return first, later, other

    first, later, other = run(body())
    spps = [first["spp"]] + [f["spp"] for f in later]
    assert spps == sorted(spps) and spps[-1] > spps[0], spps
    last = later[-1]
    assert last["image"].shape == (H, W, 3) and np.all(np.isfinite(last["image"])) and last["image"].mean() > 0
    assert last["rays"] > first["rays"] and last["samples_per_s"] > 0
    assert other["view"] == first["view"]


def test_a_camera_move_restarts_the_image(viewer):
    async def body(page):
        before = await page.until(full_frame(), "a full frame")
        before = await page.until(lambda m: full_frame(before["view"])(m) and m["spp"] >= 8, "convergence")
        await page.send({"type": "orbit", "dx": -0.2, "dy": 0.05})  # still inside the room
        restart = await page.until(lambda m: m["type"] == "frame" and m["view"] > before["view"], "the moved view")
        full = await page.until(full_frame(restart["view"]), "its first full frame")
        more = await page.until(lambda m: full_frame(restart["view"])(m) and m["spp"] > full["spp"], "it converging")
        return before, restart, full, more

    before, restart, full, more = run(with_page(viewer["url"], body))
    # The new view starts again from few samples (a coarse image first, a quarter of the resolution at one
    # sample per pixel, unless a newer frame replaced it before it was sent), then converges.
    if restart["coarse"]:
        assert restart["spp"] == 1 and restart["width"] == math.ceil(W / 4), restart
    assert full["spp"] < before["spp"] and more["spp"] > full["spp"]
    assert restart["to_world"] != before["to_world"] and restart["fov"] == before["fov"]
    assert not np.allclose(full["image"].mean(), 0)


def test_an_option_change_changes_the_statistics(viewer):
    async def body(page):
        nee = await page.until(lambda m: full_frame()(m) and m["spp"] >= 2, "a frame")
        await page.send({"type": "options", "integrator": "path", "options": {"shadow_rays": "neepp-adaptive"}})
        state = await page.until(lambda m: m["type"] == "state" and m["options"].get("shadow_rays") == "neepp-adaptive",
                                 "the new state")
        adaptive = await page.until(lambda m: full_frame()(m) and m["options"].get("shadow_rays") == "neepp-adaptive"
                                    and m["shadow_rays_skipped"] > 0, "shadow rays skipped")
        # A refused option: said why, and the options in force stay.
        await page.send({"type": "options", "integrator": "path", "options": {"no_such_option": "1"}})
        error = await page.until(lambda m: m["type"] == "error", "the error")
        kept = await page.until(lambda m: m["type"] == "state", "the state in force")
        await page.send({"type": "options", "integrator": "path", "options": {}})  # back to the scene's
        await page.until(lambda m: m["type"] == "state" and "shadow_rays" not in m["options"], "the scene's options")
        return nee, state, adaptive, error, kept

    nee, state, adaptive, error, kept = run(with_page(viewer["url"], body))
    assert nee["shadow_rays_skipped"] == 0 and nee["shadow_rays"] > 0
    assert adaptive["shadow_rays_skipped"] > 0
    assert "no_such_option" in error["message"]
    assert kept["options"] == {"shadow_rays": "neepp-adaptive"}


def test_save_writes_exr_png_statistics_and_the_map(viewer):
    async def body(page):
        await page.until(full_frame(), "a full frame")
        await page.send({"type": "save", "exposure": 1.0})
        plain = await page.until(lambda m: m["type"] in ("saved", "error"), "the save")
        # With NEE++ the map is saved too, in the project's map format.
        await page.send({"type": "options", "integrator": "path", "options": {"shadow_rays": "neepp"}})
        await page.until(lambda m: full_frame()(m) and m["options"].get("shadow_rays") == "neepp", "a NEE++ frame")
        await page.send({"type": "save"})
        with_map = await page.until(lambda m: m["type"] in ("saved", "error"), "the save with the map")
        await page.send({"type": "options", "integrator": "path", "options": {}})
        await page.until(lambda m: m["type"] == "state" and not m["options"], "the scene's options")
        return plain, with_map

    saved, with_map = run(with_page(viewer["url"], body))
    assert saved["type"] == "saved", saved
    assert with_map["type"] == "saved", with_map
    assert [Path(f).suffix for f in with_map["files"]] == [".exr", ".png", ".json", ".vis"]
    record = json.loads(Path(with_map["files"][2]).read_text())
    assert record["visibility_map"]["file"] == Path(with_map["files"][3]).name
    scene = neepp.load(DEMO, resx=W, resy=H)
    loaded = neepp.VisibilityMap.load(with_map["files"][3], scene, record["visibility_map"]["resolution"])
    assert loaded.known_pairs == record["visibility_map"]["known_pairs"] > 0
    assert record["shadow_rays"] > 0 and neepp.read_exr(with_map["files"][0]).shape[:2] == (H, W)
    exr, png, stats = (Path(f) for f in saved["files"])
    assert exr.suffix == ".exr" and png.suffix == ".png" and stats.suffix == ".json"
    assert exr.parent == viewer["out"]
    image = neepp.read_exr(exr)
    assert image.shape[:2] == (H, W) and image[..., :3].mean() > 0
    assert neepp.read_image(png).shape[:2] == (H, W)
    record = json.loads(stats.read_text())
    assert record["spp"] >= 1 and record["exposure"] == 1.0 and len(record["to_world"]) == 4
    assert record["scene"].endswith("scene.xml") and "shadow_rays" in record and "integrator" in record
    assert "visibility_map" not in record  # plain NEE keeps no map


def test_a_click_shows_the_map_view(viewer):
    """A pick (the page's click) is answered with the heat map of Ṽ from the clicked point's cell over the
    image, and the light distribution there; the image goes on converging (a pick does not restart it)."""
    # The scene's own camera (the tests before moved it) and a pixel on the floor lit by the light: its cell's
    # row of the map is seeded, so the view is the same however many passes ran before the pick is answered.
    # (A point facing away from the light, as the one at (2W/5, 3H/5) after the orbit above, has a row only
    # once one of the render's paths traced a shadow ray from its cell: after a number of passes that depends
    # on the machine's speed.)
    async def body(page):
        await page.send({"type": "reset"})
        await page.send({"type": "options", "integrator": "path", "options": {"shadow_rays": "neepp"}})
        before = await page.until(lambda m: full_frame()(m) and m["options"].get("shadow_rays") == "neepp", "a frame")
        await page.send({"type": "pick", "x": W * 3 // 4, "y": H * 4 // 5})
        mapped = await page.until(lambda m: m["type"] == "binary" and m["header"]["kind"] == "map", "the map view")
        header, data = mapped["header"], mapped["pixels"]
        after = await page.until(lambda m: full_frame(before["view"])(m) and m["spp"] > before["spp"], "more samples")
        await page.send({"type": "pick", "x": W, "y": 0})
        error = await page.until(lambda m: m["type"] == "error", "the refusal of a pixel outside")
        await page.send({"type": "options", "integrator": "path", "options": {}})
        await page.until(lambda m: m["type"] == "state" and not m["options"], "the scene's options")
        return before, header, data, after, error

    before, header, data, after, error = run(with_page(viewer["url"], body))
    assert header["hit"] and header["cell"] >= 0 and header["map"]["resolution"] == 16
    assert (header["width"], header["height"], header["channels"]) == (W, H, 1)
    heat = np.frombuffer(data, dtype="<f4").reshape(H, W)
    known = heat[np.isfinite(heat)]
    assert known.size > 0.5 * heat.size and np.all((known > 0) & (known < 1))
    assert known.max() - known.min() > 0.3, (known.min(), known.max())
    assert header["known_fraction"] == pytest.approx(known.size / heat.size)
    assert [light["pmf"] for light in header["lights"]] == [1.0] and header["light_count"] == 1
    assert after["view"] == before["view"]  # the image was not restarted
    assert "outside" in error["message"]


def test_the_relmse_against_a_reference_or_a_saved_image(viewer):
    from neepp_tools.metrics import relmse

    def binary(kind):
        def test(m):
            return m["type"] == "binary" and m["header"].get("kind") == kind
        return test

    async def body(page):
        first = await page.until(binary("reference"), "the reference, sent on connecting")
        framed = await page.until(lambda m: full_frame()(m) and "relmse" in m, "a frame with its relMSE")
        await page.send({"type": "reference", "source": "none"})
        await page.until(binary("reference"), "no reference")
        await page.until(lambda m: m["type"] == "state" and m["reference"] is None, "the state without one")
        bare = await page.until(full_frame(), "a frame")
        bare = await page.until(full_frame(), "a frame measured against nothing")
        await page.send({"type": "save"})
        saved = await page.until(lambda m: m["type"] in ("saved", "error"), "the save")
        await page.send({"type": "reference", "source": "saved"})
        stored = await page.until(binary("reference"), "the saved image as the reference")
        against = await page.until(lambda m: full_frame()(m) and "relmse" in m, "a frame against it")
        return first, framed, bare, saved, stored, against

    first, framed, bare, saved, stored, against = run(with_page(viewer["url"], body))
    ref = np.frombuffer(first["pixels"], dtype="<f4").reshape(H, W, 3)
    assert np.array_equal(ref, viewer["reference"]) and first["header"]["name"].endswith("reference.exr")
    assert framed["relmse"] == pytest.approx(relmse(framed["image"], viewer["reference"]), rel=1e-9)
    assert framed["relmse"] > 0.1 and framed["reference"].endswith("reference.exr")
    assert "relmse" not in bare
    assert saved["type"] == "saved", saved
    image = neepp.read_exr(saved["files"][0])[..., :3]
    stored_image = np.frombuffer(stored["pixels"], dtype="<f4").reshape(H, W, 3)
    assert np.array_equal(stored_image, image) and "as saved" in stored["header"]["name"]
    # Against the image it converges to: small, and the same number as neepp compare's metric gives.
    assert against["relmse"] == pytest.approx(relmse(against["image"], image), rel=1e-9)
    assert against["relmse"] < framed["relmse"]


@pytest.mark.parametrize("bad, expect", [
    ("not json", "not JSON"),
    ("[1, 2]", "JSON object"),
    ('{"type": "orbit", "dx": "left", "dy": 0}', "finite number"),
    ('{"type": "orbit", "dx": NaN, "dy": 0}', "finite number"),
    ('{"type": "orbit", "dx": 1e300, "dy": 0}', "out of range"),
    ('{"type": "pan", "dx": 0.1}', "'dy'"),
    ('{"type": "zoom", "delta": true}', "finite number"),
    ('{"type": "teleport"}', "unknown message type"),
    ('{"type": "options", "integrator": "path", "options": {"shadow_rays": 3}}', "string"),
    ('{"type": "options", "integrator": "", "options": {}}', "'integrator'"),
    ('{"type": "options", "integrator": "no-such", "options": {}}', "no-such"),
    ("[" * 5000 + "]" * 5000, "not JSON"),  # deeper than the parser goes
    ('{"type": "pick", "x": 1.5, "y": 0}', "pixel index"),
    ('{"type": "pick", "x": -1, "y": 0}', "pixel index"),
    ('{"type": "reference", "source": "/etc/passwd"}', "'source'"),
    (b"\x00\x01binary", "JSON text"),
])
def test_malformed_messages_are_refused(viewer, bad, expect):
    async def body(page):
        await page.until(lambda m: m["type"] == "state", "the state")
        if isinstance(bad, bytes):
            await page.ws.send_bytes(bad)
        else:
            await page.send(bad)
        error = await page.until(lambda m: m["type"] == "error", "the error")
        # The page is still served: a camera move still makes a new view.
        frame = await page.until(full_frame(), "a frame")
        await page.send({"type": "dolly", "amount": 0.01})
        await page.until(lambda m: m["type"] == "frame" and m["view"] > frame["view"], "a new view")
        return error

    error = run(with_page(viewer["url"], body))
    assert expect in error["message"], error
    assert viewer["proc"].poll() is None


def test_a_page_closed_and_reopened(viewer):
    """Pages that go away (closed cleanly, or their connection dropped mid-stream, as a killed tab's) leave
    the server serving: a page opened afterwards gets the state and frames, and its camera moves work."""
    async def body():
        async with aiohttp.ClientSession() as http:
            for abrupt in (False, True, False):
                ws = await http.ws_connect(viewer["url"] + "ws")
                page = Page(ws)
                await page.until(lambda m: m["type"] == "state", "the state")
                await page.until(lambda m: m["type"] == "frame", "a frame")
                await page.send({"type": "dolly", "amount": 0.01})  # frames flowing when it goes
                if abrupt:
                    ws._response.connection.transport.abort()  # no closing handshake
                await ws.close()
            async with http.ws_connect(viewer["url"] + "ws") as ws:
                page = Page(ws)
                state = await page.until(lambda m: m["type"] == "state", "the state on reopening")
                frame = await page.until(full_frame(), "a frame on reopening")
                await page.send({"type": "dolly", "amount": -0.03})
                moved = await page.until(lambda m: m["type"] == "frame" and m["view"] > frame["view"], "a new view")
                return state, moved

    state, moved = run(body())
    assert state["width"] == W and moved["view"] >= 1
    assert viewer["proc"].poll() is None


def test_an_oversized_message_closes_only_its_websocket(viewer):
    async def body():
        async with aiohttp.ClientSession() as http:
            async with http.ws_connect(viewer["url"] + "ws") as ws:
                await ws.send_str(json.dumps({"type": "dolly", "amount": 0.0, "pad": "x" * 100_000}))
                while True:
                    msg = await ws.receive(timeout=TIMEOUT)
                    if msg.type in (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSED, aiohttp.WSMsgType.CLOSING):
                        break
        return await with_page(viewer["url"], lambda page: page.until(full_frame(), "a frame after it"))

    assert run(body())["spp"] >= 1
    assert viewer["proc"].poll() is None


def _chromium():
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("chromium is not installed (scripts/test.sh installs it)")
    return [exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--no-first-run"]


async def run_in_chromium(url, profile: Path, timeout=90.0):
    """Opens url in a headless Chromium driven over its DevTools protocol (the page's self-test waits on
    the websocket in real time, which --dump-dom's virtual time would not give it) and waits for the
    self-test's verdict. Returns (verdict, console problems, every URL the page requested)."""
    log = open(profile.parent / "chromium.log", "w")
    proc = subprocess.Popen(_chromium() + [f"--user-data-dir={profile}", "--remote-debugging-port=0", "about:blank"],
                            stdout=log, stderr=log)
    problems, urls, verdict = [], [], None
    try:
        deadline = time.monotonic() + timeout
        port_file = profile / "DevToolsActivePort"
        while not (port_file.exists() and port_file.read_text().strip()):
            assert proc.poll() is None and time.monotonic() < deadline, "chromium did not start"
            await asyncio.sleep(0.1)
        port = int(port_file.read_text().split()[0])
        async with aiohttp.ClientSession() as http:
            async with http.get(f"http://127.0.0.1:{port}/json/list") as r:
                target = next(t for t in await r.json() if t["type"] == "page")
            async with http.ws_connect(target["webSocketDebuggerUrl"], max_msg_size=0) as ws:
                ids = iter(range(1, 1 << 30))

                async def call(method, **params):
                    i = next(ids)
                    await ws.send_json({"id": i, "method": method, "params": params})
                    return i

                for method in ("Runtime.enable", "Log.enable", "Network.enable"):
                    await call(method)
                await call("Page.navigate", url=url)
                asking = None
                while verdict is None and time.monotonic() < deadline:
                    if asking is None:
                        asking = await call("Runtime.evaluate", returnByValue=True,
                                            expression="(document.getElementById('selftest') || {}).textContent || ''")
                    try:
                        msg = await ws.receive_json(timeout=0.5)
                    except asyncio.TimeoutError:
                        continue
                    method, params = msg.get("method"), msg.get("params", {})
                    if method == "Runtime.exceptionThrown":
                        problems.append(params["exceptionDetails"].get("text", "exception"))
                    elif method == "Runtime.consoleAPICalled" and params["type"] in ("error", "warning", "assert"):
                        problems.append(" ".join(str(a.get("value", a.get("description"))) for a in params["args"]))
                    elif method == "Log.entryAdded" and params["entry"]["level"] in ("error", "warning"):
                        problems.append(params["entry"]["text"])
                    elif method == "Network.requestWillBeSent":
                        urls.append(params["request"]["url"])
                    elif method == "Network.webSocketCreated":
                        urls.append(params["url"])
                    elif msg.get("id") == asking:
                        text = msg.get("result", {}).get("result", {}).get("value", "")
                        if text.startswith("selftest ok") or text.startswith("selftest FAILED"):
                            verdict = text
                        asking = None
                        await asyncio.sleep(0.2)
                # The page's own list of what it loaded too: the DevTools network events of its first
                # requests can be missed when they come before Network.enable has taken effect.
                listed = await call("Runtime.evaluate", returnByValue=True,
                                    expression="performance.getEntriesByType('resource').map((e) => e.name)")
                while verdict is not None and time.monotonic() < deadline:
                    try:
                        msg = await ws.receive_json(timeout=1.0)
                    except asyncio.TimeoutError:
                        continue
                    if msg.get("id") == listed:
                        urls.extend(msg.get("result", {}).get("result", {}).get("value") or [])
                        break
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
        log.close()
    return verdict, problems, urls


def test_page_in_headless_chromium(viewer, tmp_path):
    """The page's own self-test (#selftest) in a real browser: frames converge, a mouse drag restarts the
    view, switching the shadow-ray policy to neepp-adaptive shows shadow rays skipped, a click shows the
    map's heat map over the image; no console error, and nothing requested from anywhere but the server."""
    verdict, problems, urls = run(run_in_chromium(viewer["url"] + "#selftest", tmp_path / "profile"))
    assert verdict and verdict.startswith("selftest ok"), (verdict, problems)
    assert not problems, problems
    ws_url = viewer["url"].replace("http://", "ws://")
    assert urls and all(u.startswith(viewer["url"]) or u.startswith(ws_url) for u in urls), urls
    assert any(u.endswith("/ws") for u in urls) and any(u.endswith("view.js") for u in urls), urls


def test_sigterm_stops_it_cleanly_and_frees_the_port(neepp_bin, tmp_path):
    proc, url, port = start_view(neepp_bin, tmp_path / "saved")
    try:
        async def body(page):  # a page open and frames flowing when the signal comes
            await page.until(full_frame(), "a frame")
            proc.send_signal(signal.SIGTERM)
            return await page.until(lambda m: m["type"] == "closed", "the server closing the page", timeout=20)

        run(with_page(url, body))
        assert proc.wait(timeout=20) == 0, proc.stderr.read()[-2000:]
    finally:
        if proc.poll() is None:
            proc.kill()
    assert "Traceback" not in proc.stderr.read()
    with socket.socket() as s:
        s.bind(("127.0.0.1", port))  # free again


def test_a_port_in_use_is_a_clear_error(neepp_bin, tmp_path):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        port = s.getsockname()[1]
        r = subprocess.run([str(neepp_bin), "view", str(DEMO), "-D", f"resx={W}", "-D", f"resy={H}", "--port", str(port)],
                           capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and f"127.0.0.1:{port}" in r.stderr and "Traceback" not in r.stderr, r.stderr


def test_a_reference_of_another_size_is_a_clear_error(neepp_bin, tmp_path):
    neepp.write_exr(tmp_path / "small.exr", np.zeros((4, 4, 3), np.float32))
    r = subprocess.run([str(neepp_bin), "view", str(DEMO), "-D", f"resx={W}", "-D", f"resy={H}", "--reference",
                        str(tmp_path / "small.exr")], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "4x4" in r.stderr and f"{W}x{H}" in r.stderr and "Traceback" not in r.stderr, r.stderr


def test_without_its_python_modules_it_says_what_is_missing(neepp_bin, tmp_path):
    bare = tmp_path / "bare_python"
    bare.write_text(f'#!/bin/sh\nexec "{sys.executable}" -S "$@"\n')  # -S: no site-packages
    bare.chmod(0o755)
    r = subprocess.run([str(neepp_bin), "view", str(DEMO)], capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, NEEPP_PYTHON=str(bare)))
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr[-2000:]
    assert "aiohttp" in r.stderr and "scripts/setup_python.sh" in r.stderr, r.stderr[-2000:]


def test_without_the_neepp_package_it_says_how_to_install_it(neepp_bin, tmp_path):
    """A Python with aiohttp but not the package built from the checkout (setup_python.sh without test.sh)."""
    no_package = tmp_path / "python_without_neepp"
    no_package.write_text(f"#!{sys.executable}\n"
                          "import runpy, sys\n"
                          "sys.modules['neepp'] = None  # as if not installed\n"
                          "assert sys.argv[1] == '-m'\n"
                          "module, sys.argv = sys.argv[2], sys.argv[2:]\n"
                          "runpy.run_module(module, run_name='__main__', alter_sys=True)\n")
    no_package.chmod(0o755)
    r = subprocess.run([str(neepp_bin), "view", str(DEMO)], capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, NEEPP_PYTHON=str(no_package)))
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr[-2000:]
    assert "neepp Python package" in r.stderr and "pip install" in r.stderr, r.stderr[-2000:]
