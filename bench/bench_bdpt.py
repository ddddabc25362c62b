#!/usr/bin/env python3
"""Bidirectional methods at equal time: path tracing (NEE, and NEE++'s adaptive policy), BDPT, BDPT with
NEE++'s shadow-ray rejection on its connections (bdpt-neepp-rays), BDPT with NEE++ light-path selection
(K candidates from a pool) and light tracing.

Every method gets the same wall time on each scene, twice with different seeds. The table gives relMSE
against the Mitsuba 3 reference (box-downsampled to the render's resolution), the relative variance from
the seed pair (free of the reference's own noise), efficiency = 1 / (relVar × time) relative to `path`,
samples per pixel reached, rays by kind (camera, light, shadow/connection), splats, and a sample's time
relative to a path sample.

    .venv/bin/python bench/bench_bdpt.py                                   # six scenes, 20 s each
    .venv/bin/python bench/bench_bdpt.py --scenes veach-ajar --time 10

Writes bench/out/bdpt/ (git-ignored): report.md, results.json, per-scene images and a comparison figure.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))
sys.path.insert(0, str(REPO / "bench"))

from neepp_tools import REFERENCES, SCENES_DIR, credit, exr, machine, metrics, report, runner  # noqa: E402

# name: (integrator, options)
METHODS = {
    "path": ("path", {}),
    "path-neepp": ("path", {"shadow_rays": "neepp-adaptive"}),
    "bdpt": ("bdpt", {}),
    "bdpt-neepp-rays": ("bdpt", {"shadow_rays": "neepp"}),
    "bdpt-neepp-k4": ("bdpt", {"light_paths": "neepp", "candidates": "4"}),
    "bdpt-neepp-k8": ("bdpt", {"light_paths": "neepp", "candidates": "8"}),
    "bdpt-neepp-k16": ("bdpt", {"light_paths": "neepp", "candidates": "16"}),
    "bdpt-neepp-k4-frozen": ("bdpt", {"light_paths": "neepp", "candidates": "4", "learn": "false"}),
    "light": ("light", {}),
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(REFERENCES))
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--time", type=float, default=20.0, help="wall time of every render, seconds")
    ap.add_argument("--scale", type=int, default=4, help="divide the reference resolution by this")
    ap.add_argument("--max-depth", type=int, default=17)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scenes-dir", default=str(SCENES_DIR))
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "bdpt"))
    a = ap.parse_args(argv)
    methods = a.methods.split(",")
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        ap.error(f"unknown method(s) {unknown}: one of {list(METHODS)}")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {}
    md = [f"# Bidirectional methods at equal time ({a.time:g} s each, max_depth {a.max_depth})\n\n"
          f"machine: {machine.summary()}\n"]
    for scene in a.scenes.split(","):
        W, H, _, ref_name = REFERENCES[scene]
        w, h = W // a.scale, H // a.scale
        xml = Path(a.scenes_dir) / scene / "scene.xml"
        ref = metrics.downsample(exr.read_exr(Path(a.scenes_dir) / scene / "reference" / ref_name), a.scale)
        rows, images = [], {}
        for m in methods:
            integrator, options = METHODS[m]
            runs = [runner.run_neepp(xml, out / scene / f"{m}_seed{k}.exr", time_s=a.time, resx=w, resy=h,
                                     max_depth=a.max_depth, seed=a.seed + 1000 * k, threads=a.threads,
                                     integrator=integrator, integrator_args=options,
                                     extra_args=["--rfilter", "box"], timeout=7200)
                    for k in (0, 1)]
            s = runs[0].stats
            rel_var = metrics.relative_variance(runs[0].image, runs[1].image, ref)
            row = {"method": m, "spp": s["spp"], "relMSE": metrics.relmse(runs[0].image, ref), "relVar": rel_var,
                   "mean/ref": metrics.image_mean(runs[0].image) / metrics.image_mean(ref),
                   "camera rays/spp": s["camera_rays"] / max(1, s["spp"]),
                   "light rays/spp": s["light_rays"] / max(1, s["spp"]),
                   "shadow rays/spp": s["shadow_rays"] / max(1, s["spp"]),
                   "splats/spp": s["splats"] / max(1, s["spp"]),
                   "s per spp": s["render_time_s"] / max(1, s["spp"])}
            rows.append(row)
            images[m] = runs[0].image
            print(json.dumps({"scene": scene, **row}), flush=True)
        base = next((r for r in rows if r["method"] == "path"), rows[0])
        for r in rows:
            r["efficiency vs path"] = base["relVar"] * base["s per spp"] * base["spp"] / max(
                1e-30, r["relVar"] * r["s per spp"] * r["spp"])
            r["sample cost vs path"] = r["s per spp"] / max(1e-30, base["s per spp"])
        results[scene] = rows
        md.append(f"\n## {scene} ({w}x{h}, box filter; reference {ref_name} box-downsampled ×{a.scale})\n\n")
        if credit(scene):
            md.append(f"_{credit(scene)}_\n\n")
        md.append(report.markdown_table(rows, list(rows[0].keys())) + "\n")
        report.comparison_figure(out / scene / "compare_equal_time.png", images, ref=ref,
                                 title=f"{scene}: {a.time:g} s each", credit=credit(scene))
        (out / "results.json").write_text(json.dumps(results, indent=2))
        (out / "report.md").write_text("".join(md))
    print("".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
