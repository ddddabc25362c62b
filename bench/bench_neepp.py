#!/usr/bin/env python3
"""Reproduce the NEE++ paper's tables: `nee` against each NEE++ shadow-ray policy of the path integrator,
against NEE++'s map used inside an environment light (configurations env-visibility, env-visibility-fitted),
against `-I neepp=auto` (configuration auto), and against resampled NEE with the map (ris-2, ris-4, ris-8,
ris-16: M candidates, one shadow ray).

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
high spp (EVALUATION.md): the tables state the reference used. The project's scenes (office, corridor,
courtyard, door-ajar: scenes/NAME) have no Mitsuba reference: they render at --project-res (160x90), and
their reference is neepp's own `nee` at --ref-spp (cached in the output folder), good for relVar (which
only normalizes by it) and for relMSE down to that render's noise.

Time is the render's wall time, or with --cpu-time its CPU time (with --threads 1 the steadier measure
on a machine shared with other work): the efficiency columns use it.

    .venv/bin/python bench/bench_neepp.py                                  # six scenes, 4/64/1024 spp
    .venv/bin/python bench/bench_neepp.py --scenes veach-ajar --spp 4,64   # quicker
    .venv/bin/python bench/bench_neepp.py --scenes office,bathroom --spp 64 --policies nee,ris-8 \
        --threads 1 --cpu-time --no-equal-time                              # resampling, equal spp only

Through participating media (--scenes media: door-ajar-fog, smoke-plume, sunbeam; volpath, their default
integrator) the visibility test is a transmittance estimate: the tables add the shadow rays that crossed
a medium and the density lookups per sample of the shadow rays' transmittance estimates (what a skipped
ray saves) and of the paths' free flights.

    .venv/bin/python bench/bench_neepp.py --scenes media --spp 16,64 --policies nee,neepp-adaptive,auto \
        --threads 1 --cpu-time --no-equal-time

Writes bench/out/neepp/ (git-ignored): report.md, results.json, per-scene images and error maps.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import REFERENCES, SCENES_DIR, credit, exr, machine, metrics, report, runner, scene_assets  # noqa: E402

POLICIES = ["nee", "neepp", "neepp-adaptive", "neepp-cv", "env-visibility", "auto"]
# Configurations beyond a shadow-ray policy's name (any other name is passed as shadow_rays=NAME): NEE++'s
# visibility map used inside an environment light (within_light), over the scene's grid or one fitted to
# where the camera's paths shade; `neepp=auto`, which measures on a pilot which use pays.
# And resampled NEE: M candidates, one chosen by f·Le·√Ṽ (docs/neepp.md, "Resampling with the map").
CONFIGS = {
    "nee": {},
    "auto": {"neepp": "auto"},
    "env-visibility": {"within_light": "visibility"},
    "env-visibility-fitted": {"within_light": "visibility", "grid_bounds": "shading"},
}
for _m in (2, 4, 8, 16):
    CONFIGS[f"ris-{_m}"] = {"ris": _m}
PROJECT_SCENES = REPO / "scenes"
# The project's scenes with participating media (rendered with volpath, their default): --scenes media.
MEDIA_SCENES = ["door-ajar-fog", "smoke-plume", "sunbeam"]


def config_options(policy: str) -> dict:
    """A configuration's integrator options. NAME+key=value+... adds options to NAME's (a variant, e.g.
    ris-8+light_sampler=power)."""
    name, *extra = policy.split("+")
    options = dict(CONFIGS.get(name, {"shadow_rays": name}))
    for kv in extra:
        k, eq, v = kv.partition("=")
        if not eq:
            raise SystemExit(f"configuration {policy!r}: {kv!r} is not key=value")
        options[k] = v
    return options


def render(scene_xml, out, policy, *, spp=None, time_s=None, w, h, max_depth, seed, threads, options):
    args = {**config_options(policy), **options}
    return runner.run_neepp(scene_xml, out, spp=spp, time_s=time_s, resx=w, resy=h, max_depth=max_depth,
                            seed=seed, threads=threads, integrator_args=args, extra_args=["--rfilter", "box"],
                            timeout=7200)


#: the row's column that the time ratio uses, and with the second seed's the efficiency: "render_s" (wall) or
#: "cpu_s" (--cpu-time)
TIME = {"column": "render_s"}


def row_for(policy, r, ref, base):
    s = r.stats
    rel = metrics.relmse(r.image, ref)
    row = {"policy": policy, "spp": s["spp"], "relMSE": rel, "shadow_rays": s["shadow_rays"],
           "occlusion_s": s["occlusion_time_s"], "render_s": s["render_time_s"],
           "cpu_s": s.get("render_cpu_time_s", float("nan"))}
    if s.get("medium_shadow_rays", 0):
        # Through media the visibility test is a transmittance estimate (occlusion_s is its time): the
        # density lookups it makes per sample are what a skipped shadow ray saves.
        samples = max(1, s["spp"] * s["width"] * s["height"])
        row["medium_shadow_rays"] = s["medium_shadow_rays"]
        row["tr lookups/sample"] = s.get("transmittance_lookups", 0) / samples
        row["path lookups/sample"] = s.get("density_lookups", 0) / samples
    if base is not None:
        row["relMSE ratio"] = rel / base["relMSE"]
        row["shadow ray ratio"] = s["shadow_rays"] / max(1, base["shadow_rays"])
        row["occlusion time ratio"] = s["occlusion_time_s"] / max(1e-12, base["occlusion_s"])
        row["time ratio"] = row[TIME["column"]] / max(1e-12, base[TIME["column"]])
    else:
        traced = max(1, s["shadow_rays"])
        row["unoccluded fraction"] = 1 - s.get("shadow_rays_occluded", 0) / traced
    return row


def add_variance(rows, images, render_again, ref):
    """relVar from a second render with another seed (free of the reference's floor), and efficiency
    1 / (relVar x render time) relative to the first row's (`nee`), the time the mean of the two renders'
    (one render's time alone is within the machine's +-5 % noise, as large as the differences measured)."""
    base = None
    key = {"render_s": "render_time_s", "cpu_s": "render_cpu_time_s"}[TIME["column"]]
    for row in rows:
        again = render_again(row["policy"])
        row["relVar"] = metrics.relative_variance(images[row["policy"]], again.image, ref)
        row["time of 2"] = (row[TIME["column"]] + again.stats.get(key, float("nan"))) / 2
        cost = row["relVar"] * row["time of 2"]
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


def own_reference(xml, folder, w, h, a):
    """neepp's own `nee` render of a project scene at --ref-spp, made once per resolution and depth."""
    path = folder / f"reference_nee_{w}x{h}_d{a.max_depth}_{a.ref_spp}spp.exr"
    if path.exists():
        return exr.read_exr(path)
    return runner.run_neepp(xml, path, spp=a.ref_spp, resx=w, resy=h, max_depth=a.max_depth, seed=987654,
                            threads=a.threads, extra_args=["--rfilter", "box"], timeout=7200).image


def table(rows) -> str:
    columns = list(dict.fromkeys(k for r in rows for k in r))  # union of keys, first-seen order
    return report.markdown_table(rows, columns)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(REFERENCES))
    ap.add_argument("--spp", default="4,64,1024", help="comma-separated sample counts")
    ap.add_argument("--policies", default=",".join(POLICIES),
                    help="shadow-ray policies, or configurations: " + ", ".join(CONFIGS) +
                         "; NAME+key=value adds an option (e.g. ris-8+light_sampler=power)")
    ap.add_argument("--variance", action=argparse.BooleanOptionalAction, default=True,
                    help="render every equal-spp configuration twice (another seed) for relVar and efficiency")
    ap.add_argument("--scale", type=int, default=4, help="divide the reference resolution by this")
    ap.add_argument("--equal-time-spp", type=int, default=0,
                    help="equal-time budget = nee's time at this sample count (one of --spp; default the middle "
                         "one). A longer budget weighs seeding and the machine's noise less")
    ap.add_argument("--equal-time", action=argparse.BooleanOptionalAction, default=True,
                    help="the equal-time block (every configuration again for nee's time, twice)")
    ap.add_argument("--cpu-time", action="store_true",
                    help="time ratios and efficiency from the render's CPU time instead of its wall time")
    ap.add_argument("--project-res", default="160x90", help="resolution of the project's scenes (scenes/NAME)")
    ap.add_argument("--ref-spp", type=int, default=2048, help="spp of the project scenes' own nee reference")
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
    if a.cpu_time:
        TIME["column"] = "cpu_s"
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results, md = {}, ["# NEE++ vs NEE (each scene's path or volpath integrator, max_depth %d)\n\nmachine: %s\n"
                       % (a.max_depth, machine.summary())]
    scenes = [n for name in a.scenes.split(",") for n in (MEDIA_SCENES if name == "media" else [name])]
    for scene in scenes:
        if scene in REFERENCES:
            W, H, _, ref_name = REFERENCES[scene]
            w, h = W // a.scale, H // a.scale
            xml = Path(a.scenes_dir) / scene / "scene.xml"
            ref = metrics.downsample(exr.read_exr(Path(a.scenes_dir) / scene / "reference" / ref_name), a.scale)
            about_ref = f"Mitsuba 3 {ref_name} box-downsampled ×{a.scale}"
        else:
            w, h = (int(x) for x in a.project_res.split("x"))
            xml = PROJECT_SCENES / scene / "scene.xml"
            if not xml.exists():
                ap.error(f"unknown scene {scene!r}: neither a Bitterli scene ({', '.join(REFERENCES)}) nor {xml}")
            scene_assets.ensure_scene_assets(scene)  # generated files (the smoke plume's density grid)
            ref = own_reference(xml, out / scene, w, h, a)
            about_ref = f"neepp nee, {a.ref_spp} spp"
        md.append(f"\n## {scene} ({w}x{h}, box filter; reference: {about_ref}; time: {TIME['column']})\n")
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
        (out / "results.json").write_text(json.dumps(results, indent=2))
        (out / "report.md").write_text("".join(md))
        if not a.equal_time:
            continue
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
