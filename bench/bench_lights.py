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

from bench_neepp import downsample, table  # noqa: E402
from neepp_tools import REFERENCES, SCENES_DIR, credit, exr, metrics, report, runner  # noqa: E402

SAMPLERS = ["power", "uniform", "spatial", "bvh", "visibility", "visibility-power", "visibility-bvh"]
MANY_LIGHT_SCENES = ["office", "corridor", "courtyard"]
BASELINES = ["uniform", "power", "spatial"]


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
    a = ap.parse_args(argv)
    samplers, policies = a.samplers.split(","), a.policies.split(",")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results, md, summary = {}, [f"# Light selection ({a.spp} spp and equal time)\n"], []

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
        # Targets at equal time, over every policy combination.
        eq = [r | {"policy": p} for p, rows in results[scene]["equal_time"].items() for r in rows]
        best = {n: min((r for r in eq if r["sampler"] == n), key=lambda r: r["relMSE"], default=None)
                for n in samplers}
        base_best = min((best[n] for n in BASELINES if best.get(n)), key=lambda r: r["relMSE"], default=None)
        vis = min((best[n] for n in ("visibility", "visibility-power", "visibility-bvh") if best.get(n)),
                  key=lambda r: r["relMSE"],
                  default=None)
        if vis and base_best:
            line = {"scene": scene, "best baseline": f"{base_best['sampler']}+{base_best['policy']}",
                    "baseline relMSE": base_best["relMSE"], "best visibility": f"{vis['sampler']}+{vis['policy']}",
                    "visibility relMSE": vis["relMSE"], "vis / baseline": vis["relMSE"] / base_best["relMSE"]}
            if best.get("bvh"):
                line["bvh relMSE"] = best["bvh"]["relMSE"]
                line["vis / bvh"] = vis["relMSE"] / best["bvh"]["relMSE"]
            summary.append(line)
        (out / "results.json").write_text(json.dumps({"scenes": results, "summary": summary}, indent=2))
        (out / "report.md").write_text("".join(md) + "\n## Summary (equal time, best policy per sampler)\n\n" +
                                       (table(summary) if summary else "") + "\n")
    print((out / "report.md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
