#!/usr/bin/env python3
"""neepp view's targets (issue 41), measured on the viewer's own renderer (neepp_tools.view.ViewSession and
neepp._neepp.LiveRender), without the web page:

  move to first image  the time from a camera command to the first image of the new view (the coarse one:
                       a quarter of the resolution, one sample per pixel), median of --moves moves
  updates per second   full-resolution images of the new view delivered in the --window seconds after a
                       move (those of its first pass, its finished tiles over the coarse image, included)
  first-second relVar  the relative variance of a new view's image after its first second (wall time from
                       the render's start, the fresh render's map seeding included) with the map kept from
                       --train seconds of the previous view, against a fresh NEE++ render of the new view:
                       per-pixel variance across --seeds renders of each, over (mean^2 + 0.01), the mean of
                       all of them (the same normalization for both, so the ratio is the variances')

The targets (not timed tests): on the 2-core machine at 480x270, the first image within 100 ms, at least 10
updates a second, and a first-second relVar with the map kept at most 0.8x a fresh render's.

    .venv/bin/python bench/bench_view.py                            # door-ajar and office, 480x270
    .venv/bin/python bench/bench_view.py --scenes door-ajar --seeds 3

Prints a table and writes bench/out/view/results.json (git-ignored). Timings depend on the machine's
load: run it on a quiet one, and say what else ran.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import threading
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

import neepp  # noqa: E402
from neepp_tools.view.orbit import OrbitCamera  # noqa: E402
from neepp_tools.view.session import ViewSession  # noqa: E402

SCENES = {"door-ajar": REPO / "scenes" / "door-ajar" / "scene.xml", "office": REPO / "scenes" / "office" / "scene.xml"}


def load(name, width, height):
    return neepp.load(SCENES[name], resx=width, resy=height)


def responsiveness(name, args, options):
    """(median ms from a move to the first image, median full images per second after a move)."""
    session = ViewSession(load(name, args.width, args.height), "path", options, max_spp=1 << 20,
                          threads=args.threads)
    frames = []  # (time, view, coarse)
    got = threading.Condition()

    def on_frame(frame):
        with got:
            frames.append((time.perf_counter(), frame.view, frame.stats["coarse"]))
            got.notify_all()

    session.on_frame = on_frame
    session.start()
    latencies, rates = [], []
    try:
        time.sleep(args.warmup)  # the first view: the map is seeded and learns
        for i in range(args.moves):
            view = session._generation + 1
            start = time.perf_counter()
            session.camera_command({"type": "orbit", "dx": 0.05 if i % 2 == 0 else -0.05, "dy": 0.0})
            with got:
                got.wait_for(lambda: any(v == view for _, v, _ in frames), timeout=30)
            first = next(t for t, v, _ in frames if v == view)
            latencies.append(1000 * (first - start))
            time.sleep(args.window)
            full = [t for t, v, c in frames if v == view and not c and t - first <= args.window]
            rates.append(len(full) / args.window)
    finally:
        session.stop()
    return statistics.median(latencies), statistics.median(rates)


def first_second(name, args, options, keep_map, seed):
    """The image of the moved view after --budget seconds of rendering it, and its spp."""
    scene = load(name, args.width, args.height)
    live = neepp._neepp.LiveRender(scene, "path", options, args.threads, "", seed)
    cam = OrbitCamera(scene.camera["to_world"], scene.camera["fov"], scene.bounds)
    if keep_map:
        timed_render(live, args.train)  # the previous view: the map is seeded and learns
    cam.orbit(0.1, 0.02)
    live.set_camera(cam.to_world(), cam.fov)
    return timed_render(live, args.budget)


def timed_render(live, seconds):
    """Renders until `seconds` of wall time have passed (at the end of a pass); the last image and spp."""
    out = {}
    start = time.perf_counter()

    def on_frame(image, info):
        out["image"], out["spp"] = image, info["spp"]
        if time.perf_counter() - start >= seconds:
            live.cancel()

    live.render(1 << 20, 1, 0.02, on_frame)
    live.clear_cancel()
    return out["image"], out["spp"]


def kept_vs_fresh(name, args, options):
    kept = [first_second(name, args, options, True, 100 + s) for s in range(args.seeds)]
    fresh = [first_second(name, args, options, False, 200 + s) for s in range(args.seeds)]
    images_k, images_f = np.array([k[0] for k in kept]), np.array([f[0] for f in fresh])
    mean = np.concatenate([images_k, images_f]).mean(axis=0)

    def relvar(images):
        return float(np.mean(images.var(axis=0, ddof=1) / (mean ** 2 + 0.01)))

    return (relvar(images_k), relvar(images_f), statistics.median(k[1] for k in kept),
            statistics.median(f[1] for f in fresh))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scenes", default="door-ajar,office")
    p.add_argument("--width", type=int, default=480)
    p.add_argument("--height", type=int, default=270)
    p.add_argument("--threads", type=int, default=0, help="0: all cores")
    p.add_argument("--shadow-rays", default="neepp", help="the NEE++ policy of both renders")
    p.add_argument("--moves", type=int, default=5)
    p.add_argument("--warmup", type=float, default=3.0, help="seconds of the first view before the moves")
    p.add_argument("--window", type=float, default=2.0, help="seconds of each new view counted")
    p.add_argument("--train", type=float, default=3.0, help="seconds of the previous view the kept map learned")
    p.add_argument("--budget", type=float, default=1.0, help="the new view's seconds whose relVar is measured")
    p.add_argument("--seeds", type=int, default=4)
    args = p.parse_args()
    options = {"shadow_rays": args.shadow_rays}
    rows = []
    for name in args.scenes.split(","):
        latency, rate = responsiveness(name, args, options)
        rv_kept, rv_fresh, spp_kept, spp_fresh = kept_vs_fresh(name, args, options)
        rows.append({"scene": name, "width": args.width, "height": args.height, "options": options,
                     "move_to_first_image_ms": latency, "updates_per_s": rate, "relvar_kept": rv_kept,
                     "relvar_fresh": rv_fresh, "relvar_ratio": rv_kept / rv_fresh, "spp_kept": spp_kept,
                     "spp_fresh": spp_fresh})
        r = rows[-1]
        print(f"{name:10s} {args.width}x{args.height}: move -> first image {latency:6.1f} ms, {rate:5.1f} updates/s, "
              f"first {args.budget:g} s relVar kept/fresh {r['relvar_ratio']:.3f} "
              f"({rv_kept:.4g} at {spp_kept} spp / {rv_fresh:.4g} at {spp_fresh} spp)", flush=True)
    out = REPO / "bench" / "out" / "view"
    out.mkdir(parents=True, exist_ok=True)
    conditions = {"cpus": os.cpu_count(), "load_average": os.getloadavg(), "args": vars(args)}
    (out / "results.json").write_text(json.dumps({"conditions": conditions, "rows": rows}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
