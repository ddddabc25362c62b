#!/usr/bin/env python3
"""Benchmark neepp `volpath` against Mitsuba 3 `llvm_ad_rgb` `volpath` on scenes with participating media.

Scenes: the project's media scenes (scenes/door-ajar-fog, smoke-plume, sunbeam; rendered at --res, their
`max_depth` set to --max-depth) and, with --mitsuba-data ROOT (a checkout of mitsuba-renderer/mitsuba-data,
see bench/mitsuba_suite.py), the heterogeneous scenes of Mitsuba 3's render suite
(tests/scenes/participating_media/test_hetero_*) and the documentation's subsurface scenes
(docs/scenes/medium_homogeneous_sss*.xml, at the resolution their files give), rendered as published. Both renderers render each scene at the same spp, interleaved (taking turns to go first),
--reps times with seeds 0..reps-1. The table gives the median samples/s of each, the neepp/Mitsuba
ratio per rep (median and range), and each image's mean (sum of RGB) relative to the other's, which
for the same scene and integrator should agree within noise.

    .venv/bin/python bench/bench_volpath.py                                  # the project's scenes
    .venv/bin/python bench/bench_volpath.py --mitsuba-data ~/mitsuba-data --reps 3 --spp 64

samples/s is pixels*spp / render time as each renderer reports it (Mitsuba's includes Dr.Jit's kernel
compilation, scene loading excluded). The machine is shared and noisy: compare ratios from one run only.
Writes bench/out/volpath/ (git-ignored): results.json, report.md and the EXRs.
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import exr, machine, report, runner, scene_assets  # noqa: E402

PROJECT_MEDIA_SCENES = ["door-ajar-fog", "smoke-plume", "sunbeam"]


def scene_list(a) -> list[dict]:
    """Each scene: its file, a name, and how to render it (resolution or as published)."""
    w, h = (int(x) for x in a.res.split("x"))
    scenes = []
    for name in a.scenes.split(","):
        if name:
            scene_assets.ensure_scene_assets(name)
            scenes.append({"name": name, "xml": REPO / "scenes" / name / "scene.xml", "res": (w, h)})
    if a.mitsuba_data:
        root = Path(a.mitsuba_data).expanduser()
        suite = root / "tests" / "scenes" / "participating_media"
        for xml in sorted(suite.glob("test_hetero_*_volpath*.xml")):
            scenes.append({"name": xml.stem, "xml": xml,
                           "published": {"integrator": "volpath", "res": a.suite_res}})
        docs = root / "docs" / "scenes"
        for xml in sorted(docs.glob("medium_homogeneous_sss*.xml")):
            scenes.append({"name": xml.stem, "xml": xml, "published": {}})
    return scenes


def image_mean(img) -> float:
    return float(img[..., :3].sum(axis=-1).mean())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(PROJECT_MEDIA_SCENES), help="project scenes (scenes/NAME)")
    ap.add_argument("--mitsuba-data", default="", help="mitsuba-data checkout: adds the suite's heterogeneous "
                    "scenes and the documentation's subsurface scenes")
    ap.add_argument("--res", default="320x180", help="resolution of the project scenes")
    ap.add_argument("--suite-res", type=int, default=128, help="resolution of the suite's scenes (theirs: 48)")
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--max-depth", type=int, default=12, help="max_depth of the project scenes")
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--timeout", type=float, default=3600)
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "volpath"))
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    ok, why = runner.mitsuba_available(a.variant)
    if not ok:
        print(f"Mitsuba 3 ({a.variant}) is unavailable: {why}", file=sys.stderr)
        return 2

    results = {"spp": a.spp, "reps": a.reps, "variant": a.variant, "time": time.strftime("%Y-%m-%d %H:%M:%S"),
               "machine": machine.describe(), "scenes": {}}
    rows = []
    for sc in scene_list(a):
        name, xml, res = sc["name"], sc["xml"], sc.get("res")
        published = sc.get("published")
        runs = {"neepp": [], "mitsuba": []}

        def render_neepp(rep):
            defines = dict(published) if published is not None else {"max_depth": a.max_depth}
            if res:
                defines.update(resx=res[0], resy=res[1])
            r = runner.run_neepp(xml, out / f"{name}_neepp_s{rep}.exr", spp=a.spp, seed=rep,
                                 threads=a.threads or None, defines=defines,
                                 integrator="volpath" if published is not None else None, timeout=a.timeout)
            runs["neepp"].append({"samples_per_s": r.stats["samples_per_s"], "mean": image_mean(r.image)})

        def render_mitsuba(rep):
            if published is not None:
                r = runner.run_mitsuba(xml, out / f"{name}_mitsuba_s{rep}.exr", variant=a.variant, spp=a.spp,
                                       seed=rep, threads=a.threads, timeout=a.timeout, as_published=True,
                                       defines={**published, "spp": a.spp})
            else:
                r = runner.run_mitsuba(xml, out / f"{name}_mitsuba_s{rep}.exr", variant=a.variant, resx=res[0],
                                       resy=res[1], spp=a.spp, max_depth=a.max_depth, seed=rep,
                                       integrator="volpath", threads=a.threads, timeout=a.timeout)
            runs["mitsuba"].append({"samples_per_s": r.stats["samples_per_s"], "mean": image_mean(r.image)})

        for rep in range(a.reps):
            order = [render_neepp, render_mitsuba]
            for render_one in (order if rep % 2 == 0 else order[::-1]):
                render_one(rep)
        ratios = [n["samples_per_s"] / m["samples_per_s"] for n, m in zip(runs["neepp"], runs["mitsuba"])]
        n_sps = statistics.median(x["samples_per_s"] for x in runs["neepp"])
        m_sps = statistics.median(x["samples_per_s"] for x in runs["mitsuba"])
        n_mean = statistics.fmean(x["mean"] for x in runs["neepp"])
        m_mean = statistics.fmean(x["mean"] for x in runs["mitsuba"])
        row = {"scene": name, "neepp Msamples/s": n_sps / 1e6, "Mitsuba Msamples/s": m_sps / 1e6,
               "ratio": statistics.median(ratios), "ratio range": f"{min(ratios):.3g}-{max(ratios):.3g}",
               "mean neepp/Mitsuba": n_mean / m_mean if m_mean else float("nan")}
        rows.append(row)
        results["scenes"][name] = {"runs": runs, "row": row}
        print(json.dumps(row), flush=True)
        (out / "results.json").write_text(json.dumps(results, indent=2))
    md = (f"# neepp volpath vs Mitsuba 3 {a.variant} volpath, {a.spp} spp, {a.reps} reps\n\nmachine: "
          f"{machine.summary()}\n\n" + report.markdown_table(rows, list(rows[0])) + "\n") if rows else ""
    (out / "report.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
