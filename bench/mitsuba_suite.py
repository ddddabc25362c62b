#!/usr/bin/env python3
"""Mitsuba 3's render regression suite on neepp, judged as Mitsuba 3's own harness judges Mitsuba.

The suite is the `tests/scenes` folder of the public repository mitsuba-renderer/mitsuba-data (never
committed here). Get it once, anywhere, and pass its root (or set MITSUBA_DATA):

    git clone --depth 1 https://github.com/mitsuba-renderer/mitsuba-data ~/mitsuba-data
    .venv/bin/python bench/mitsuba_suite.py ~/mitsuba-data                  # all scenes, harness spp
    .venv/bin/python bench/mitsuba_suite.py ~/mitsuba-data --scale 0.25 --scenes bsdf_spheres

What Mitsuba 3's src/render/tests/test_renders.py does for a scalar RGB variant, and so this script:
- every `tests/scenes/*/*.xml` is a test; the suffix of its name after the last '_' is the integrator,
  passed to the scene as the parameter `integrator`, with `spp` (the scenes declare both);
- the sample count is 2e6 / (the reference's pixel count), seed 0;
- the reference is `refs/<name without the suffix>_ref_rgb.exr` with its per-sample variance image
  `..._ref_rgb_var.exr`; image, reference and variance are compared in XYZ;
- each pixel channel gets a two-sided z-test p-value, |mean - ref| sqrt(spp / max(var, 1e-4)), against
  a Šidák-corrected level 1 - 0.99^(1/pixels); the render passes when at least 99.75 % of the pixel
  channels pass.
neepp renders with the build's binary (NEEPP_BIN or build/neepp). --scale F renders F times the harness's
sample count (the test stays valid, it only loses power); scenes with participating media render with
neepp's volpath. Columns: loads (or the first error), the pass fraction, neepp's mean over the reference's
(sum of RGB), and mean z^2, which for an unbiased render estimates neepp's per-sample variance over the
reference's. --mitsuba adds the same columns for Mitsuba 3 (pip, scalar_rgb) as a control. Mitsuba 3
chooses among emitters uniformly (or by their sampling_weight) where neepp's path tracer defaults to a light
BVH: on scenes with several lights `-I light_sampler=uniform` makes the noise, and so mean z^2, the same
as Mitsuba's.

Writes bench/out/mitsuba_suite/ (git-ignored): the renders, results.json and table.md.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import exr, metrics, report, runner  # noqa: E402

SAMPLE_BUDGET = 2_000_000  # samples per image in the harness
PASS_FRACTION = 0.9975
SIGNIFICANCE = 0.01


def scene_folder(data: Path) -> Path:
    """The suite's scene folder, given mitsuba-data's root or the folder itself."""
    for c in (data / "tests" / "scenes", data):
        if c.is_dir() and any(c.glob("*/*.xml")):
            return c
    raise SystemExit(f"no Mitsuba render-test scenes under {data} (expected tests/scenes/*/*.xml; "
                     "git clone https://github.com/mitsuba-renderer/mitsuba-data)")


def suite_scenes(folder: Path) -> list[Path]:
    return sorted(folder.glob("*/*.xml"))


def integrator_of(scene: Path) -> str:
    return scene.stem.rsplit("_", 1)[-1]


def reference_files(scene: Path) -> tuple[Path, Path]:
    ref = scene.parent / "refs" / (scene.stem.rsplit("_", 1)[0] + "_ref_rgb.exr")
    return ref, ref.with_name(ref.stem + "_var.exr")


def harness_spp(width: int, height: int, scale: float = 1.0) -> int:
    return max(1, int(SAMPLE_BUDGET // (width * height) * scale))


def included_files(scene: Path, seen=None) -> list[Path]:
    """The scene file and the files its <include> elements name, recursively (relative to the including
    file's folder; a file not found there is left out)."""
    seen = seen if seen is not None else []
    if scene in seen or not scene.is_file():
        return seen
    seen.append(scene)
    for name in re.findall(r"<include\s[^>]*filename\s*=\s*[\"']([^\"']+)", scene.read_text(errors="replace")):
        included_files((scene.parent / name).resolve(), seen)
    return seen


def uses_media(scene: Path) -> bool:
    return any("<medium" in f.read_text(errors="replace") for f in included_files(scene.resolve()))


def first_error(log: str, folder: Path | None = None) -> str:
    """The first line of a failed run's output that says what went wrong, without the renderer's prefix
    and with paths relative to folder."""
    lines = [ln.strip() for ln in log.splitlines() if ln.strip()]
    found = next((ln for ln in lines if re.search(r"error|unsupported|not supported|cannot|unknown|invalid|failed",
                                                  ln, re.I) and not re.match(r"(neepp|mitsuba) failed \(rc=", ln)),
                 lines[-1] if lines else "failed")
    found = re.sub(r"^(neepp: error: |RuntimeError: )", "", found)
    found = re.sub(r"^\S*\[[\w.]+:\d+\] (At )?", "", found)  # Mitsuba's source location
    return found.replace(f"{folder}/", "") if folder else found


def judge(img_rgb, spp: int, ref_rgb, ref_var_rgb) -> dict:
    """The harness's test of a render (RGB) against the reference and its variance image (RGB files)."""
    if img_rgb.shape[:2] != ref_rgb.shape[:2]:
        return {"pass_fraction": 0.0, "mean_ratio": float("nan"), "mean_z2": float("nan"), "passed": False,
                "note": f"size {img_rgb.shape[1]}x{img_rgb.shape[0]}, reference {ref_rgb.shape[1]}x{ref_rgb.shape[0]}"}
    img, ref, var = (metrics.rgb_to_xyz(x) for x in (img_rgb, ref_rgb, ref_var_rgb))
    frac = metrics.z_test_pass_fraction(img, spp, ref, var, SIGNIFICANCE)
    mref = float(np.sum(ref_rgb[..., :3], dtype=np.float64))
    return {"pass_fraction": frac,
            "mean_ratio": float(np.sum(img_rgb[..., :3], dtype=np.float64)) / mref if mref else float("nan"),
            "mean_z2": metrics.mean_z_squared(img, spp, ref, var),
            "passed": frac >= PASS_FRACTION}


def table_row(rec: dict, with_mitsuba: bool) -> dict:
    """One line of the table from a scene's record (results.json)."""
    def cells(res, prefix=""):
        if "error" in res:
            return {f"{prefix}loads": res["error"]}
        if "pass_fraction" not in res:
            return {f"{prefix}loads": res.get("status", "")}
        return {f"{prefix}loads": "yes", f"{prefix}z pass": f"{100 * res['pass_fraction']:.2f} %",
                f"{prefix}mean ratio": f"{res['mean_ratio']:.4f}", f"{prefix}mean z²": f"{res['mean_z2']:.2f}",
                f"{prefix}result": "pass" if res["passed"] else "FAIL"}
    columns = ["loads", "z pass", "mean ratio", "mean z²", "result"]
    row = {"scene": rec["scene"], "spp": rec.get("spp")} | dict.fromkeys(columns) | cells(rec)
    if with_mitsuba:
        row |= dict.fromkeys(f"mi {c}" for c in columns) | cells(rec.get("mitsuba", {}), "mi ")
    return row


def summary_of(results: list[dict]) -> str:
    line = (f"{len(results)} scenes ({sum(bool(r.get('media')) for r in results)} with media): neepp loads "
            f"{sum(r['status'] == 'loads' for r in results)}, passes {sum(bool(r.get('passed')) for r in results)}")
    if any("mitsuba" in r for r in results):
        line += f"; Mitsuba 3 passes {sum(bool(r.get('mitsuba', {}).get('passed')) for r in results)}"
    return line


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("data", nargs="?", default=os.environ.get("MITSUBA_DATA"),
                    help="mitsuba-data's root (or its tests/scenes); default $MITSUBA_DATA")
    ap.add_argument("--scenes", default="", help="comma-separated substrings of the scene paths to run")
    ap.add_argument("--scale", type=float, default=1.0, help="fraction of the harness's sample count")
    ap.add_argument("--spp", type=int, default=0, help="this sample count instead of the harness's")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=1800, help="seconds per render")
    ap.add_argument("-I", dest="options", action="append", default=[], help="neepp integrator option k=v")
    ap.add_argument("--neepp-arg", action="append", default=[], help="extra argument for neepp render")
    ap.add_argument("--mitsuba", action="store_true", help="also run Mitsuba 3 (scalar_rgb) through the test")
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "mitsuba_suite"))
    a = ap.parse_args(argv)
    if not a.data:
        ap.error("give mitsuba-data's folder (or set MITSUBA_DATA); "
                 "git clone https://github.com/mitsuba-renderer/mitsuba-data")
    folder = scene_folder(Path(a.data).expanduser())
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    options = dict(o.split("=", 1) for o in a.options)
    wanted = [s for s in a.scenes.split(",") if s]

    results = []
    for scene in suite_scenes(folder):
        name = f"{scene.parent.name}/{scene.stem}"
        if wanted and not any(w in name for w in wanted):
            continue
        rec = {"scene": name, "integrator": integrator_of(scene), "media": uses_media(scene)}
        results.append(rec)
        ref_path, var_path = reference_files(scene)
        if not (ref_path.exists() and var_path.exists()):
            rec["status"] = "no rgb reference"
        else:
            run_scene(scene, ref_path, var_path, rec, a, options, out, folder)
        print(json.dumps(rec), flush=True)

    table = report.markdown_table([table_row(r, a.mitsuba) for r in results])
    summary = (summary_of(results) +
               f" (spp: {a.spp if a.spp else f'{a.scale:g} x the harness'}; neepp options {options or 'default'})")
    (out / "results.json").write_text(json.dumps(results, indent=2))
    (out / "table.md").write_text(table + "\n\n" + summary + "\n")
    print(table)
    print(summary)
    return 0


def run_scene(scene, ref_path, var_path, rec, a, options, out, folder):
    """Render the scene with neepp (and Mitsuba 3 with --mitsuba) and record the harness's verdicts."""
    ref, var = exr.read_exr(ref_path), exr.read_exr(var_path)
    spp = rec["spp"] = a.spp or harness_spp(ref.shape[1], ref.shape[0], a.scale)
    stem = f"{scene.parent.name}_{scene.stem}"
    try:
        r = runner.run_neepp(scene, out / f"{stem}_neepp.exr", spp=spp, seed=0, threads=a.threads or None,
                             defines={"integrator": rec["integrator"]}, integrator_args=options,
                             extra_args=a.neepp_arg, timeout=a.timeout)
        rec.update(status="loads", render_s=r.wall_s, **judge(r.image, spp, ref, var))
    except runner.RenderError as e:
        rec.update(status="error", error=first_error(str(e), folder))
    if a.mitsuba:
        try:
            m = runner.run_mitsuba(scene, out / f"{stem}_mitsuba.exr", variant="scalar_rgb", spp=spp, seed=0,
                                   defines={"spp": spp, "integrator": rec["integrator"]}, as_published=True,
                                   timeout=a.timeout)
            rec["mitsuba"] = judge(m.image, spp, ref, var)
        except runner.RenderError as e:
            rec["mitsuba"] = {"error": first_error(str(e), folder)}


if __name__ == "__main__":
    sys.exit(main())
