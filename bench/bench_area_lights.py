#!/usr/bin/env python3
"""Solid-angle against area sampling of area lights (issue 44): `-I area_light_sampling=solid-angle`
against the default `area`, at equal spp, one thread, CPU time.

Every configuration renders twice (seeds S and S + 1000): relVar is the pair's per-pixel variance over
(ref^2 + 0.01) (neepp_tools.metrics.relative_variance), with ref the mean of all four renders of the scene
(the same normalization for both strategies, so their ratio is the variance's); time is the two renders'
CPU time. Efficiency = 1 / (relVar x time); the table gives the solid-angle strategy's ratios to area's.

Scenes: the Bitterli scenes at their reference resolution / --scale, and the project's scenes (scenes/NAME)
at --project-res. All their area lights are rectangles or spheres.

    NEEPP_BIN=build/neepp .venv/bin/python bench/bench_area_lights.py                   # ~25 min on one core
    .venv/bin/python bench/bench_area_lights.py --scenes cornell-box,office --spp 16    # quicker

Writes bench/out/area_lights/ (git-ignored): report.md, results.json.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import REFERENCES, SCENES_DIR, machine, metrics, runner  # noqa: E402

SCENES = ["bathroom", "veach-ajar", "cornell-box", "staircase", "office", "corridor", "door-ajar", "courtyard"]
STRATEGIES = ["area", "solid-angle"]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--scale", type=int, default=4, help="divide the Bitterli scenes' reference resolution by this")
    ap.add_argument("--project-res", default="160x90", help="resolution of the project's scenes")
    ap.add_argument("--max-depth", type=int, default=17)
    ap.add_argument("--integrator", default="path")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("-I", dest="options", action="append", default=[], help="extra integrator option k=v")
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "area_lights"))
    a = ap.parse_args(argv)
    extra = dict(o.split("=", 1) for o in a.options)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {}
    lines = [f"# Area lights: solid-angle vs area sampling ({a.integrator}, {a.spp} spp, one thread, CPU time)\n",
             f"machine: {machine.summary()}\n",
             "| scene | res | lights taken | relVar area | relVar solid | relVar ratio | time ratio | efficiency ratio |",
             "|---|---|---|---|---|---|---|---|"]
    for scene in a.scenes.split(","):
        if scene in REFERENCES:
            W, H, _, _ = REFERENCES[scene]
            w, h = W // a.scale, H // a.scale
            xml = SCENES_DIR / scene / "scene.xml"
        else:
            w, h = (int(x) for x in a.project_res.split("x"))
            xml = REPO / "scenes" / scene / "scene.xml"
        runs = {}
        for strategy in STRATEGIES:
            pair = []
            for k in range(2):
                r = runner.run_neepp(xml, out / scene / f"{strategy}_{k}.exr", spp=a.spp, resx=w, resy=h,
                                     max_depth=a.max_depth, seed=a.seed + 1000 * k, threads=1,
                                     integrator=a.integrator,
                                     integrator_args={"area_light_sampling": strategy, **extra},
                                     extra_args=["--rfilter", "box"], timeout=7200)
                pair.append(r)
            runs[strategy] = pair
        ref = np.mean([r.image for pair in runs.values() for r in pair], axis=0)
        row = {"resolution": f"{w}x{h}"}
        for strategy, pair in runs.items():
            rel_var = metrics.relative_variance(pair[0].image, pair[1].image, ref)
            cpu = sum(r.stats["render_cpu_time_s"] for r in pair)
            row[strategy] = {"relVar": rel_var, "cpu_s": cpu, "efficiency": 1.0 / (rel_var * cpu)}
        within = runs["solid-angle"][0].stats.get("integrator_statistics", {}).get("within_light", {})
        row["lights_taken"] = within.get("solid_angle_lights", "?")
        A, S = row["area"], row["solid-angle"]
        row["relVar ratio"] = S["relVar"] / A["relVar"]
        row["time ratio"] = S["cpu_s"] / A["cpu_s"]
        row["efficiency ratio"] = S["efficiency"] / A["efficiency"]
        results[scene] = row
        lines.append(f"| {scene} | {w}x{h} | {row['lights_taken']} | {A['relVar']:.4g} | {S['relVar']:.4g} | "
                     f"{row['relVar ratio']:.3f} | {row['time ratio']:.3f} | {row['efficiency ratio']:.3f} |")
        print(lines[-1], flush=True)
        (out / "results.json").write_text(json.dumps(results, indent=2))
        (out / "report.md").write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
