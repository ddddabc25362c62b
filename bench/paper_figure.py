#!/usr/bin/env python3
"""The paper's comparison figure (Path, MLT, BDPT and NEE++ side by side), made with `neepp compare`:
each scene rendered with path tracing without NEE (the paper's "Path"), with NEE, with NEE++'s two
shadow-ray policies, BDPT, BDPT with NEE++ light-path selection and PSSMLT, at equal time and at equal
sample counts (the slides' 16, 64 and 128 spp), at 1/SCALE of the Mitsuba 3 reference's resolution
(box filter, max_depth 17), two seeds each (for the relative variance).

Then the issue's targets: on bathroom and veach-ajar, whether an NEE++ method is the best at equal time
(by relative variance, free of the reference's own error) or within 10 % of the best; and, with
--pssmlt-means, whether PSSMLT's image mean is within 1 % of the reference's on all six scenes.

    .venv/bin/python bench/paper_figure.py                         # bathroom, classroom, veach-ajar, 10 s
    .venv/bin/python bench/paper_figure.py --scenes bathroom --time 30 --spp 16,64,128
    .venv/bin/python bench/paper_figure.py --scenes '' --spp '' --pssmlt-means 64    # PSSMLT's means only

Writes bench/out/paper_figure/ (git-ignored): <scene>/equal_time/index.html (and equal_spp_N/), and
summary.md / summary.json with every scene's table.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import REFERENCES, SCENES_DIR, compare, credit, machine, reference_path, scene_xml  # noqa: E402

METHODS = ["path:nee=false", "path", "path:shadow_rays=neepp", "path:shadow_rays=neepp-adaptive", "bdpt",
           "bdpt:light_paths=neepp:candidates=4", "pssmlt"]
NEEPP = {m for m in METHODS if "neepp" in m}
TARGET_SCENES = ("bathroom", "veach-ajar")


def run_compare(scene: str, out: Path, scale: int, seeds: int, time_s: float | None, spp: int | None,
                binary: str | None) -> dict:
    w, h, depth, _ = REFERENCES[scene]
    args = [str(scene_xml(scene)), "--methods", ",".join(METHODS), "--seeds", str(seeds), "--reference",
            str(reference_path(scene)), "--rfilter", "box", "-D", f"resx={w // scale}", "-D", f"resy={h // scale}",
            "-D", f"max_depth={depth}", "-o", str(out)]
    args += ["--spp", str(spp)] if spp else ["--time", str(time_s)]
    if binary:
        args += ["--neepp", binary]
    if compare.main(args) != 0:
        raise SystemExit(f"paper_figure: neepp compare failed on {scene}")
    return json.loads((out / "results.json").read_text())


def pssmlt_means(spp: int, scale: int, seeds: int, binary: str | None, out: Path) -> list[str]:
    """PSSMLT's image mean on every shared scene against the reference's (the issue's 1 % target)."""
    from neepp_tools import exr, metrics, runner

    lines = ["| scene | pssmlt mean | reference mean | difference | seeds x spp | time (s) |", "|---|---|---|---|---|---|"]
    for scene, (w, h, depth, _) in REFERENCES.items():
        if not scene_xml(scene).exists():
            continue
        ref = metrics.downsample(exr.read_exr(reference_path(scene)), scale)
        means, times = [], []
        for s in range(seeds):
            r = runner.run_neepp(scene_xml(scene), out / "pssmlt_means" / f"{scene}_{s}.exr", spp=spp, resx=w // scale,
                                 resy=h // scale, max_depth=depth, seed=40 + s, integrator="pssmlt", binary=binary,
                                 extra_args=["--rfilter", "box"])
            means.append(metrics.image_mean(r.image))
            times.append(r.stats["render_time_s"])
        m, mr = sum(means) / len(means), metrics.image_mean(ref)
        lines.append(f"| {scene} | {m:.5g} | {mr:.5g} | {m / mr - 1:+.2%} | {seeds} x {spp} | {sum(times):.1f} |")
        print(lines[-1], flush=True)
    return lines


def table(results: dict) -> list[str]:
    best_var = min(m["rel_variance"] for m in results["methods"])
    lines = ["| method | relMSE | rel. variance | × best | mean FLIP | spp | shadow rays | time (s) |",
             "|---|---|---|---|---|---|---|---|"]
    for m in results["methods"]:
        lines.append(f"| {m['label']} | {m['relmse']:.4g} | {m['rel_variance']:.4g} | "
                     f"{m['rel_variance'] / best_var:.2f} | {m['mean_flip']:.4f} | {m['spp']} | "
                     f"{m['shadow_rays']:,} | {m['render_time_s']:.2f} |")
    return lines


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenes", default="bathroom,classroom,veach-ajar")
    p.add_argument("--time", type=float, default=10.0, help="seconds per method and seed at equal time")
    p.add_argument("--spp", default="16,64,128", help="equal-sample-count comparisons ('' for none)")
    p.add_argument("--scale", type=int, default=4)
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--neepp", default=None)
    p.add_argument("--pssmlt-means", type=int, default=0, metavar="SPP",
                   help="also render PSSMLT at SPP on all six scenes and compare its mean with the reference's")
    p.add_argument("-o", "--out", type=Path, default=REPO / "bench" / "out" / "paper_figure")
    a = p.parse_args()
    summary = {"machine": machine.describe(), "time_s": a.time, "scale": a.scale, "scenes": {}}
    md = [f"# The paper's figure: equal time {a.time} s and equal spp, 1/{a.scale} resolution, {a.seeds} seeds",
          "", f"Machine: {machine.summary()}", ""]
    for scene in [s for s in a.scenes.split(",") if s]:
        if not scene_xml(scene).exists():
            print(f"paper_figure: {scene} is absent from {SCENES_DIR}, skipped", file=sys.stderr)
            continue
        entry = {"equal_time": run_compare(scene, a.out / scene / "equal_time", a.scale, a.seeds, a.time, None, a.neepp)}
        for spp in [int(s) for s in a.spp.split(",") if s]:
            entry[f"equal_spp_{spp}"] = run_compare(scene, a.out / scene / f"equal_spp_{spp}", a.scale, a.seeds,
                                                   None, spp, a.neepp)
        methods = entry["equal_time"]["methods"]
        best = min(methods, key=lambda m: m["rel_variance"])
        best_neepp = min((m for m in methods if m["label"] in NEEPP), key=lambda m: m["rel_variance"])
        entry["best"] = best["label"]
        entry["best_neepp"] = best_neepp["label"]
        entry["best_neepp_vs_best"] = best_neepp["rel_variance"] / best["rel_variance"]
        summary["scenes"][scene] = entry
        md += [f"## {scene}", ""]
        if credit(scene):
            md += [f"*{credit(scene)}*", ""]
        for key, res in entry.items():
            if not isinstance(res, dict):
                continue
            md += [f"### {key.replace('_', ' ')}", ""] + table(res) + [""]
        verdict = "the best" if best_neepp is best else f"{entry['best_neepp_vs_best']:.2f}x the best ({best['label']})"
        md += [f"Best at equal time (relative variance): {best['label']}; best NEE++ method {best_neepp['label']}: "
               f"{verdict}." + (" Target (within 10 %): " + ("met" if entry["best_neepp_vs_best"] <= 1.1 else "missed")
                                if scene in TARGET_SCENES else ""), ""]
    if a.pssmlt_means:
        md += ["## PSSMLT's image mean against the reference", ""] + pssmlt_means(a.pssmlt_means, a.scale, a.seeds,
                                                                                  a.neepp, a.out) + [""]
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    (a.out / "summary.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
