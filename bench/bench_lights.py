#!/usr/bin/env python3
"""Light-selection benchmark (issue: light selection): every light sampler of the path integrator, with
plain NEE and with an NEE++ shadow-ray policy, at equal spp and at equal time.

Scenes: the project's many-light scenes (scenes/office, scenes/corridor, scenes/courtyard, at their own
resolution, reference: a Mitsuba 3 llvm render at --ref-spp, cached under .cache/) and the six Bitterli
scenes (reference resolution / --scale, box filter, against the shared reference box-downsampled), which
have one light each: there every sampler must match power (no loss on single-light scenes).

For each scene and policy the rows give relMSE against the reference, shadow rays traced, the fraction
of them that were occluded, render time, and ratios to `power`. Equal time gives every sampler the wall
time `power` + `nee` needed at --spp. The summary checks the targets: visibility-aware selection ≥ 20 %
lower relMSE than the best of uniform/power/spatial at equal time, and not worse than the light BVH.

    .venv/bin/python bench/bench_lights.py                                # all scenes, ~1 h on 2 cores
    .venv/bin/python bench/bench_lights.py --scenes office --spp 16        # quicker

Writes bench/out/lights/ (git-ignored): report.md, results.json, per-scene comparison figures.
The reference's own noise is a floor under every relMSE and pulls ratios toward 1.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_neepp import table  # noqa: E402
from neepp_tools import REFERENCES, SCENES_DIR, credit, exr, machine, metrics, report, runner  # noqa: E402
from neepp_tools.metrics import downsample  # noqa: E402

SAMPLERS = ["power", "uniform", "spatial", "spatial-oriented", "bvh", "visibility", "visibility-power", "visibility-bvh"]
MANY_LIGHT_SCENES = ["office", "corridor", "courtyard"]
BASELINES = ["uniform", "power", "spatial"]
SUMMARY_NOTE = """
"vis / baseline": relMSE of the best visibility-aware sampler over the best of uniform/power/spatial,
each with its best shadow-ray policy, at equal time (target ≤ 0.8); "vis / bvh": over the light BVH
(target ≤ 1); "vis / spatial-oriented": over the spatial estimate with the same orientation-aware
tables as `visibility` (ours; what the map adds on top of orientation). The "from equal spp" columns estimate the same ratios as relMSE × render time. With one
light every sampler is power (identical images at equal spp): their equal-time differences are timing
noise, and show how large that noise is on this machine.
"""


def scene_setup(scene, a):
    """(xml, width, height, max_depth, reference image, reference description, extra renderer args)."""
    if scene in REFERENCES:
        W, H, _, ref_name = REFERENCES[scene]
        w, h = W // a.scale, H // a.scale
        ref = downsample(exr.read_exr(Path(a.scenes_dir) / scene / "reference" / ref_name), a.scale)
        return (Path(a.scenes_dir) / scene / "scene.xml", w, h, 17, ref,
                f"Mitsuba 3 {ref_name} box-downsampled ×{a.scale}", ["--rfilter", "box"])
    xml = REPO / "scenes" / scene / "scene.xml"
    probe = runner.run_neepp(xml, Path(a.out) / scene / "probe.exr", spp=1, threads=a.threads)
    w, h = probe.stats["width"], probe.stats["height"]
    ref = runner.run_mitsuba(xml, spp=a.ref_spp, max_depth=a.max_depth, resx=w, resy=h, cache=True, timeout=7200)
    return xml, w, h, a.max_depth, ref.image, f"Mitsuba 3 llvm_ad_rgb, {a.ref_spp} spp", []


VISIBILITY = ["visibility", "visibility-power", "visibility-bvh"]


def summary_line(scene: str, result: dict) -> dict | None:
    """The targets' comparison for one scene, over every sampler × policy combination: the best
    visibility-aware sampler against the best baseline and against the BVH, at equal time, and the same
    estimated from the equal-spp runs as relMSE × render time (free of a time-limited run's whole-pass
    granularity, not of timing noise)."""
    def best(mode, key):
        rows = [r | {"policy": p, "relMSE x time": r["relMSE"] * r["render_s"]}
                for p, rs in result.get(mode, {}).items() for r in rs]
        out = {}
        for r in rows:
            if r["sampler"] not in out or r[key] < out[r["sampler"]][key]:
                out[r["sampler"]] = r
        return out

    def pick(b, names, key):
        return min((b[n] for n in names if n in b), key=lambda r: r[key], default=None)

    et, es = best("equal_time", "relMSE"), best("equal_spp", "relMSE x time")
    base, vis = pick(et, BASELINES, "relMSE"), pick(et, VISIBILITY, "relMSE")
    if not base or not vis:
        return None
    line = {"scene": scene, "best baseline": f"{base['sampler']}+{base['policy']}", "baseline relMSE": base["relMSE"],
            "best visibility": f"{vis['sampler']}+{vis['policy']}", "visibility relMSE": vis["relMSE"],
            "vis / baseline": vis["relMSE"] / base["relMSE"]}
    if "bvh" in et:
        line["bvh relMSE"] = et["bvh"]["relMSE"]
        line["vis / bvh"] = vis["relMSE"] / et["bvh"]["relMSE"]
    if "spatial-oriented" in et:  # ours: what orientation alone buys, without visibility
        line["vis / spatial-oriented"] = vis["relMSE"] / et["spatial-oriented"]["relMSE"]
    e_base, e_vis = pick(es, BASELINES, "relMSE x time"), pick(es, VISIBILITY, "relMSE x time")
    line["from equal spp: vis / baseline"] = e_vis["relMSE x time"] / e_base["relMSE x time"]
    if "bvh" in es:
        line["from equal spp: vis / bvh"] = e_vis["relMSE x time"] / es["bvh"]["relMSE x time"]
    return line


def summarize(paths) -> str:
    """Summary table of one or more results.json files (e.g. of runs over different scene sets)."""
    lines = []
    for path in paths:
        data = json.loads(Path(path).read_text())
        lines += [summary_line(scene, r) for scene, r in data["scenes"].items()]
    return table([x for x in lines if x]) + "\n" + SUMMARY_NOTE


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(MANY_LIGHT_SCENES + list(REFERENCES)))
    ap.add_argument("--samplers", default=",".join(SAMPLERS))
    ap.add_argument("--policies", default="nee,neepp,neepp-adaptive", help="shadow-ray policies to combine with")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096, help="Mitsuba reference spp (many-light scenes)")
    ap.add_argument("--scale", type=int, default=4, help="Bitterli scenes: divide the reference resolution")
    ap.add_argument("--max-depth", type=int, default=12, help="many-light scenes (Bitterli: 17)")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scenes-dir", default=str(SCENES_DIR))
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "lights"))
    ap.add_argument("--summarize", nargs="+", metavar="RESULTS_JSON",
                    help="only print the summary table of earlier runs' results.json files")
    a = ap.parse_args(argv)
    if a.summarize:
        print(summarize(a.summarize))
        return 0
    samplers, policies = a.samplers.split(","), a.policies.split(",")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results, md, summary = {}, [f"# Light selection ({a.spp} spp and equal time)\n\nmachine: {machine.summary()}\n"], []

    for scene in a.scenes.split(","):
        xml, w, h, depth, ref, ref_desc, extra = scene_setup(scene, a)
        md.append(f"\n## {scene} ({w}x{h}, max_depth {depth}; reference: {ref_desc})\n")
        if credit(scene):
            md.append(f"_{credit(scene)}_\n")
        results[scene] = {}

        def render(sampler, policy, name, **kw):
            args = {"light_sampler": sampler}
            if policy != "nee":
                args["shadow_rays"] = policy
            return runner.run_neepp(xml, out / scene / name, resx=w, resy=h, max_depth=depth, seed=a.seed,
                                    threads=a.threads, integrator_args=args, extra_args=extra, timeout=7200, **kw)

        budget = None
        for mode in ("equal_spp", "equal_time"):
            for policy in policies:
                rows, images, base = [], {}, None
                for sampler in samplers:
                    kw = {"spp": a.spp} if mode == "equal_spp" else {"time_s": budget}
                    r = render(sampler, policy, f"{mode}_{policy}_{sampler}.exr", **kw)
                    s = r.stats
                    lights = s.get("lights")
                    row = {"sampler": sampler, "spp": s["spp"], "relMSE": metrics.relmse(r.image, ref),
                           "shadow_rays": s["shadow_rays"],
                           "occluded": s.get("shadow_rays_occluded", 0) / max(1, s["shadow_rays"]),
                           "render_s": s["render_time_s"]}
                    base = base or row
                    row["relMSE ratio"] = row["relMSE"] / base["relMSE"]
                    row["shadow ray ratio"] = row["shadow_rays"] / max(1, base["shadow_rays"])
                    rows.append(row)
                    images[sampler] = r.image
                    print(json.dumps({"scene": scene, "mode": mode, "policy": policy, **row}), flush=True)
                    if mode == "equal_spp" and budget is None and sampler == samplers[0]:
                        budget = s["render_time_s"]  # the first sampler's (power's) time with the first policy
                results[scene].setdefault(mode, {})[policy] = rows
                title = f"{mode.replace('_', ' ')}" + (f" ({budget:.2f} s)" if mode == "equal_time" else f" ({a.spp} spp)")
                md.append(f"\n### {title}, shadow rays: {policy}\n\n" + table(rows) + "\n")
                report.comparison_figure(out / scene / f"compare_{mode}_{policy}.png", images, ref=ref,
                                         title=f"{scene}: {title}, {policy}", credit=credit(scene))
        line = summary_line(scene, results[scene])
        if line:
            summary.append(line | {"lights": lights})
        (out / "results.json").write_text(json.dumps({"scenes": results, "summary": summary}, indent=2))
        (out / "report.md").write_text("".join(md) + "\n## Summary (equal time, best policy per sampler)\n\n" +
                                       (table(summary) if summary else "") + "\n" + SUMMARY_NOTE)
    print((out / "report.md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
