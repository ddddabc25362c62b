#!/usr/bin/env python3
"""Reproduce the NEE++ paper's tables: `nee` against each NEE++ shadow-ray policy of the path integrator,
against NEE++'s map used inside an environment light (configurations env-visibility, env-visibility-fitted),
and against `-I neepp=auto` (configuration auto).

For every scene, at each sample count (default 4, 64, 1024) every policy renders the same scene with the
same seed; the tables give, with ratios to `nee`: relMSE against the reference, shadow rays traced,
time inside occlusion queries (visibility-test time) and total render time. An equal-time block then
gives each policy the wall time `nee` needed at the middle sample count and compares relMSE, and, from
a second render with another seed, relVar: the variance alone, free of the reference's floor. The
equal-spp tables get the same second render (unless --no-variance) and with it the efficiency,
1 / (relVar x time), relative to `nee`'s: what issue 28 measures. For `nee` the unoccluded fraction of
its shadow rays (the oracle's best possible ratio) is reported too.

Resolution: the reference's divided by --scale (default 4, e.g. 160x90 for classroom), rendered with a
box filter and compared against the Mitsuba 3 reference box-downsampled by the same factor, so the
footprints agree. The reference's own noise is a floor under every relMSE and pulls ratios toward 1 at
high spp (EVALUATION.md): the tables state the reference used.

    .venv/bin/python bench/bench_neepp.py                                  # six scenes, 4/64/1024 spp
    .venv/bin/python bench/bench_neepp.py --scenes veach-ajar --spp 4,64   # quicker

Writes bench/out/neepp/ (git-ignored): report.md, results.json, per-scene images and error maps.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import REFERENCES, SCENES_DIR, credit, exr, machine, metrics, report, runner  # noqa: E402

POLICIES = ["nee", "neepp", "neepp-adaptive", "neepp-cv", "env-visibility", "auto"]
# Configurations beyond a shadow-ray policy's name (any other name is passed as shadow_rays=NAME): NEE++'s
# visibility map used inside an environment light (within_light), over the scene's grid or one fitted to
# where the camera's paths shade; and `neepp=auto`, which measures on a pilot which use pays.
CONFIGS = {
    "nee": {},
    "auto": {"neepp": "auto"},
    "env-visibility": {"within_light": "visibility"},
    "env-visibility-fitted": {"within_light": "visibility", "grid_bounds": "shading"},
}


def config_options(policy: str) -> dict:
    return dict(CONFIGS.get(policy, {"shadow_rays": policy}))


def render(scene_xml, out, policy, *, spp=None, time_s=None, w, h, max_depth, seed, threads, options):
    args = {**config_options(policy), **options}
    return runner.run_neepp(scene_xml, out, spp=spp, time_s=time_s, resx=w, resy=h, max_depth=max_depth,
                            seed=seed, threads=threads, integrator_args=args, extra_args=["--rfilter", "box"],
                            timeout=7200)


def row_for(policy, r, ref, base):
    s = r.stats
    rel = metrics.relmse(r.image, ref)
    row = {"policy": policy, "spp": s["spp"], "relMSE": rel, "shadow_rays": s["shadow_rays"],
           "occlusion_s": s["occlusion_time_s"], "render_s": s["render_time_s"]}
    if base is not None:
        row["relMSE ratio"] = rel / base["relMSE"]
        row["shadow ray ratio"] = s["shadow_rays"] / max(1, base["shadow_rays"])
        row["occlusion time ratio"] = s["occlusion_time_s"] / max(1e-12, base["occlusion_s"])
        row["time ratio"] = s["render_time_s"] / max(1e-12, base["render_s"])
    else:
        traced = max(1, s["shadow_rays"])
        row["unoccluded fraction"] = 1 - s.get("shadow_rays_occluded", 0) / traced
    return row


def add_variance(rows, images, render_again, ref):
    """relVar from a second render with another seed (free of the reference's floor), and efficiency
    1 / (relVar x render time) relative to the first row's (`nee`)."""
    base = None
    for row in rows:
        again = render_again(row["policy"])
        row["relVar"] = metrics.relative_variance(images[row["policy"]], again.image, ref)
        cost = row["relVar"] * row["render_s"]
        base = base or cost
        if base is not cost:
            row["relVar ratio"] = row["relVar"] / rows[0]["relVar"]
            # No sample in the budget (seeding took it all): nothing was bought.
            row["efficiency"] = base / cost if cost > 0 and row["spp"] > 0 else 0.0
        print(json.dumps(row), flush=True)


def run_policies(policies, name, ref, render_one):
    """Renders every policy with render_one(policy, out_name) -> RenderResult; rows (ratios to the first,
    `nee`) and images."""
    rows, base, images = [], None, {}
    for policy in policies:
        r = render_one(policy, f"{policy}_{name}.exr")
        row = row_for(policy, r, ref, base)
        base = base or row
        rows.append(row)
        images[policy] = r.image
        print(json.dumps(row), flush=True)
    return rows, images


def table(rows) -> str:
    columns = list(dict.fromkeys(k for r in rows for k in r))  # union of keys, first-seen order
    return report.markdown_table(rows, columns)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(REFERENCES))
    ap.add_argument("--spp", default="4,64,1024", help="comma-separated sample counts")
    ap.add_argument("--policies", default=",".join(POLICIES),
                    help="shadow-ray policies, or configurations: " + ", ".join(CONFIGS))
    ap.add_argument("--variance", action=argparse.BooleanOptionalAction, default=True,
                    help="render every equal-spp configuration twice (another seed) for relVar and efficiency")
    ap.add_argument("--scale", type=int, default=4, help="divide the reference resolution by this")
    ap.add_argument("--equal-time-spp", type=int, default=0,
                    help="equal-time budget = nee's time at this sample count (one of --spp; default the middle "
                         "one). A longer budget weighs seeding and the machine's noise less")
    ap.add_argument("--max-depth", type=int, default=17)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("-I", dest="options", action="append", default=[], help="extra integrator option k=v")
    ap.add_argument("--scenes-dir", default=str(SCENES_DIR))
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "neepp"))
    a = ap.parse_args(argv)
    options = dict(o.split("=", 1) for o in a.options)
    spps = [int(x) for x in a.spp.split(",")]
    if a.equal_time_spp and a.equal_time_spp not in spps:
        ap.error(f"--equal-time-spp {a.equal_time_spp} is not one of --spp {a.spp}")
    policies = a.policies.split(",")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results, md = {}, ["# NEE++ vs NEE (path integrator, max_depth %d)\n\nmachine: %s\n" % (a.max_depth, machine.summary())]
    for scene in a.scenes.split(","):
        W, H, _, ref_name = REFERENCES[scene]
        w, h = W // a.scale, H // a.scale
        xml = Path(a.scenes_dir) / scene / "scene.xml"
        ref = metrics.downsample(exr.read_exr(Path(a.scenes_dir) / scene / "reference" / ref_name), a.scale)
        md.append(f"\n## {scene} ({w}x{h}, box filter; reference: Mitsuba 3 {ref_name} box-downsampled ×{a.scale})\n")
        if credit(scene):
            md.append(f"_{credit(scene)}_\n")
        results[scene] = {"equal_spp": {}, "equal_time": {}}
        for spp in spps:
            rows, images = run_policies(policies, f"{spp}spp", ref, lambda policy, name: render(
                xml, out / scene / name, policy, spp=spp, w=w, h=h, max_depth=a.max_depth, seed=a.seed,
                threads=a.threads, options=options))
            if a.variance:
                add_variance(rows, images, lambda policy: render(
                    xml, out / scene / f"{policy}_{spp}spp_seed2.exr", policy, spp=spp, w=w, h=h,
                    max_depth=a.max_depth, seed=a.seed + 1000, threads=a.threads, options=options), ref)
            results[scene]["equal_spp"][spp] = rows
            md.append(f"\n### equal spp: {spp}\n\n" + table(rows) + "\n")
            report.comparison_figure(out / scene / f"compare_{spp}spp.png", images, ref=ref,
                                     title=f"{scene}: {spp} spp", credit=credit(scene))
        # Equal time: every policy gets the wall time `nee` used at the middle (or chosen) sample count.
        mid = a.equal_time_spp or spps[len(spps) // 2]
        budget = next(r for r in results[scene]["equal_spp"][mid] if r["policy"] == "nee")["render_s"]
        rows, equal_time_images = run_policies(policies, "equal_time", ref, lambda policy, name: render(
            xml, out / scene / name, policy, time_s=budget, w=w, h=h, max_depth=a.max_depth, seed=a.seed,
            threads=a.threads, options=options))
        # The same again with another seed: the pair's difference measures each policy's variance without
        # the reference's floor (at high spp relMSE against the reference is mostly that floor, which
        # pulls every ratio toward 1).
        add_variance(rows, equal_time_images, lambda policy: render(
            xml, out / scene / f"{policy}_equal_time_seed2.exr", policy, time_s=budget, w=w, h=h,
            max_depth=a.max_depth, seed=a.seed + 1000, threads=a.threads, options=options), ref)
        results[scene]["equal_time"] = {"budget_s": budget, "rows": rows}
        md.append(f"\n### equal time: {budget:.2f} s (nee's time at {mid} spp)\n\n" + table(rows) + "\n")
        (out / "results.json").write_text(json.dumps(results, indent=2))
        (out / "report.md").write_text("".join(md))
    print("".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
