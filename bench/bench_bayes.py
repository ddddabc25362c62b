#!/usr/bin/env python3
"""Bayesian light selection (issue 44): `light_sampler=bayes` / `bayes-va` (Vévoda et al. 2018 on our light
BVH and voxel grid) against the light BVH and NEE++'s visibility-aware choices, on the project's many-light
scenes, by efficiency = 1 / (relVar × time) (EVALUATION.md): relVar from two renders that differ only in
their seed (no reference needed, free of a reference's own noise), time the render time of the pair.

    NEEPP_BIN=build/neepp .venv/bin/python bench/bench_bayes.py --spp 16 --repeats 2

Prints a table per scene (median over repeats, and the spread) with ratios to `bvh`, and writes
bench/out/bayes/results.json. The machine is shared: ratios are taken within one run, and `uptime` is
printed with them.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import metrics, runner  # noqa: E402

SAMPLERS = ["bvh", "visibility", "visibility-bvh", "bayes", "bayes-va"]
SCENES = ["office", "corridor", "courtyard"]


def measure(scene: str, sampler: str, a, repeat: int) -> dict:
    xml = REPO / "scenes" / scene / "scene.xml"
    out = Path(a.out) / scene
    imgs, time_s, stats = [], 0.0, None
    for k in range(2):
        seed = 1000 * repeat + 2 * k + 1
        r = runner.run_neepp(xml, out / f"{sampler}_{k}.exr", spp=a.spp, seed=seed, threads=a.threads,
                             resx=a.resx, resy=a.resy, integrator_args={"light_sampler": sampler})
        imgs.append(r.image)
        time_s += r.stats.get("render_time_s", r.wall_s)
        stats = r.stats
    ref = (imgs[0] + imgs[1]) / 2
    rel_var = metrics.relative_variance(imgs[0], imgs[1], ref)
    return {"rel_var": rel_var, "time_s": time_s / 2, "efficiency": 1 / (rel_var * time_s / 2),
            "shadow_rays": stats.get("shadow_rays"), "passes": stats.get("passes")}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenes", nargs="+", default=SCENES)
    p.add_argument("--samplers", nargs="+", default=SAMPLERS)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--resx", type=int, default=None)
    p.add_argument("--resy", type=int, default=None)
    p.add_argument("--repeats", type=int, default=2)
    p.add_argument("--threads", type=int, default=None)
    p.add_argument("--out", default=str(REPO / "bench" / "out" / "bayes"))
    a = p.parse_args()
    load = os.popen("uptime").read().strip()
    print(f"machine: {load}")
    results = {}
    for scene in a.scenes:
        rows = {s: [] for s in a.samplers}
        for rep in range(a.repeats):  # samplers interleaved within a repeat, so load drifts hit all alike
            for s in a.samplers:
                rows[s].append(measure(scene, s, a, rep))
        results[scene] = rows
        base = statistics.median(r["efficiency"] for r in rows["bvh"]) if "bvh" in rows else None
        print(f"\n{scene} ({a.spp} spp, {a.repeats} repeats; median [min-max])")
        print("| sampler | relVar | time s | efficiency / bvh |")
        print("|---|---|---|---|")
        for s, rs in rows.items():
            effs = [r["efficiency"] / base for r in rs] if base else [r["efficiency"] for r in rs]
            print(f"| {s} | {statistics.median(r['rel_var'] for r in rs):.4g} | "
                  f"{statistics.median(r['time_s'] for r in rs):.2f} | "
                  f"{statistics.median(effs):.2f} [{min(effs):.2f}-{max(effs):.2f}] |")
    load_after = os.popen("uptime").read().strip()
    print(f"\nmachine after: {load_after}")
    Path(a.out).mkdir(parents=True, exist_ok=True)
    (Path(a.out) / "results.json").write_text(json.dumps({"args": vars(a), "uptime": [load, load_after],
                                                          "results": results}, indent=1))


if __name__ == "__main__":
    main()
