#!/usr/bin/env python3
"""Benchmark neepp `path` against Mitsuba 3 `llvm_ad_rgb` `path` on the evaluation scenes.

For each scene (default: classroom 640x360, bathroom 512x512; always the reference's resolution and
max_depth 17) both renderers render at the same spp, interleaved (taking turns to go first), `--reps` times
with seeds 0..reps-1; the table gives medians (and the spread) of samples/s, the neepp/Mitsuba ratio of each
rep's pair of runs (median, range, geometric mean, and how many reps neepp won with the exact sign test's
p, metrics.paired_ratios: one rep of a pair can fall either side of 1 on this machine), relMSE of each against
../shared/scenes/<scene>/reference/, the relative variance of each (from pairs of seeds, with 2+ reps:
relMSE minus relVar is bias² plus the reference's own noise, so a relMSE gap with equal relVar is a
bias), and peak memory (each process's own peak resident set, VmHWM: neepp's stats' peak_memory_mb;
Mitsuba: the worker's, Python and Mitsuba's libraries included).
bench/out/ (git-ignored) receives results.json, report.md, the EXRs, and per scene a side-by-side PNG
with false-colour relMSE maps.

    .venv/bin/python bench/bench_path.py                 # classroom + bathroom, 64 spp, 2 reps
    .venv/bin/python bench/bench_path.py --quick         # 16 spp, 1 rep
    .venv/bin/python bench/bench_path.py --scenes veach-ajar,cornell-box --spp 32 --reps 3

samples/s is pixels*spp / render_time_s as each renderer reports it (neepp: its stats; Mitsuba: the
mi.render call incl. Dr.Jit's kernel compilation, scene loading excluded); load s is each renderer's scene
loading (parsing, meshes, textures, acceleration structure); wall_s is the whole process.
The machine is shared and noisy: compare ratios from one run only.
"""
from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import embree_floor  # noqa: E402

from neepp_tools import REFERENCES, SCENES_DIR, credit, exr, machine, metrics, report, runner  # noqa: E402


FLOOR_NOTE = """
Embree floor: samples/s if a sample cost only its ray queries (bench/embree_floor.py: a 2 spp render's rays
recorded and traced again by Embree alone); neepp ray share: neepp's samples/s over the floor, the part of
its time that is ray queries; floor/Mitsuba: the largest ratio reachable without fewer or cheaper rays.
"""


def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def spread(xs):
    xs = [x for x in xs if x is not None]
    return (min(xs), max(xs)) if len(xs) > 1 else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default="classroom,bathroom", help="comma-separated scene names")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--max-depth", type=int, default=17)
    ap.add_argument("--quick", action="store_true", help="16 spp, 1 rep (overrides --spp/--reps)")
    ap.add_argument("--threads", type=int, default=0, help="threads for both renderers (0: all)")
    ap.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (llvm_ad_rgb or scalar_rgb)")
    ap.add_argument("--scenes-dir", default=str(SCENES_DIR))
    ap.add_argument("--out", default=str(REPO / "bench" / "out"))
    ap.add_argument("--skip-neepp", action="store_true")
    ap.add_argument("--skip-mitsuba", action="store_true")
    ap.add_argument("--timeout", type=float, default=1800.0, help="per render, seconds")
    ap.add_argument("--no-floor", action="store_true",
                    help="skip the Embree floor (bench/embree_floor.py: a 2 spp render's rays replayed alone)")
    a = ap.parse_args(argv)
    if a.quick:
        a.spp, a.reps = 16, 1

    scenes_dir = Path(a.scenes_dir)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    scenes = [s.strip() for s in a.scenes.split(",") if s.strip()]
    for s in scenes:
        if s not in REFERENCES:
            ap.error(f"unknown scene {s}; known: {', '.join(REFERENCES)}")
    if not (scenes_dir / scenes[0] / "scene.xml").exists():
        print(f"scenes not found under {scenes_dir}", file=sys.stderr)
        return 2

    neepp = None if a.skip_neepp else runner.find_neepp()
    if neepp is None and not a.skip_neepp:
        print("note: neepp binary not found (NEEPP_BIN or build/neepp); benchmarking Mitsuba only", file=sys.stderr)
    use_mi = not a.skip_mitsuba
    if use_mi:
        ok, why = runner.mitsuba_available(a.variant)
        if not ok:
            print(f"note: Mitsuba unavailable ({why}); benchmarking neepp only", file=sys.stderr)
            use_mi = False
    if neepp is None and not use_mi:
        print("nothing to benchmark", file=sys.stderr)
        return 2

    results = {"spp": a.spp, "reps": a.reps, "max_depth": a.max_depth, "variant": a.variant,
               "threads": a.threads or os.cpu_count(), "neepp": str(neepp) if neepp else None,
               "loadavg_start": os.getloadavg(), "time": time.strftime("%Y-%m-%d %H:%M:%S"),
               "machine": machine.describe(), "scenes": {}}
    rows = []
    for scene in scenes:
        w, h, _, _ = REFERENCES[scene]
        xml = scenes_dir / scene / "scene.xml"
        ref = exr.read_exr(scenes_dir / scene / "reference" / REFERENCES[scene][3])
        runs = {"neepp": [], "mitsuba": []}
        images = {"neepp": [], "mitsuba": []}  # per rep, for relVar and the figures (the last rep's)

        def render_neepp(rep):
            r = runner.run_neepp(xml, out / f"{scene}_neepp_s{rep}.exr", spp=a.spp, resx=w, resy=h,
                                 max_depth=a.max_depth, seed=rep, threads=a.threads or None,
                                 integrator="path", binary=neepp, timeout=a.timeout)
            st = r.stats
            rt = st.get("render_time_s")
            runs["neepp"].append({
                "seed": rep, "render_time_s": rt, "load_time_s": st.get("load_time_s"), "wall_s": r.wall_s,
                "samples_per_s": st.get("samples_per_s") or (w * h * a.spp / rt if rt else None),
                "peak_memory_mb": st.get("peak_memory_mb"), "peak_rss_mb": r.peak_rss_mb,
                "rays": st.get("rays"), "shadow_rays": st.get("shadow_rays"),
                **metrics.all_metrics(r.image, ref)})
            images["neepp"].append(r.image)
            print(f"[{scene}] neepp   rep {rep}: {runs['neepp'][-1]['samples_per_s'] or 0:,.0f} samples/s, "
                  f"relMSE {runs['neepp'][-1]['relmse']:.4g}", file=sys.stderr, flush=True)

        def render_mitsuba(rep):
            r = runner.run_mitsuba(xml, out / f"{scene}_mitsuba_s{rep}.exr", variant=a.variant, resx=w,
                                   resy=h, spp=a.spp, max_depth=a.max_depth, seed=rep,
                                   threads=a.threads, timeout=a.timeout)
            st = r.stats
            runs["mitsuba"].append({
                "seed": rep, "render_time_s": st["render_time_s"], "load_time_s": st["load_time_s"],
                "wall_s": r.wall_s, "samples_per_s": st["samples_per_s"],
                "peak_memory_mb": st.get("peak_memory_mb", r.peak_rss_mb), "peak_rss_mb": r.peak_rss_mb,
                **metrics.all_metrics(r.image, ref)})
            images["mitsuba"].append(r.image)
            print(f"[{scene}] mitsuba rep {rep}: {st['samples_per_s']:,.0f} samples/s, "
                  f"relMSE {runs['mitsuba'][-1]['relmse']:.4g}", file=sys.stderr, flush=True)

        renderers = ([render_neepp] if neepp is not None else []) + ([render_mitsuba] if use_mi else [])
        for rep in range(a.reps):
            # The two renderers take turns going first, so that whatever a run leaves behind for the next
            # (page cache, the other core's load, clock drift over the pair) falls on each alike.
            for render_one in (renderers if rep % 2 == 0 else renderers[::-1]):
                render_one(rep)
        summ = {}
        for k, rs in runs.items():
            if rs:
                summ[k] = {m: med([x.get(m) for x in rs]) for m in
                           ("samples_per_s", "render_time_s", "load_time_s", "wall_s", "relmse", "rmse", "mean_abs_rel_error",
                            "mean_ratio", "peak_memory_mb", "shadow_rays", "rays")}
                summ[k]["samples_per_s_range"] = spread([x.get("samples_per_s") for x in rs])
                # Relative variance from pairs of seeds: what of relMSE is noise (the rest is bias² plus the
                # reference's own noise, the same for both renderers).
                pairs = list(itertools.combinations(images[k], 2))
                summ[k]["relvar"] = (statistics.fmean(metrics.relative_variance(x, y, ref) for x, y in pairs)
                                     if pairs else None)
        floor = None
        if neepp is not None and not a.no_floor and all(p.exists() for p in embree_floor.tools_beside(neepp)):
            with tempfile.TemporaryDirectory(prefix="neepp_floor_") as tmp:
                floor = embree_floor.ray_floor(xml, {"resx": w, "resy": h, "max_depth": a.max_depth}, neepp,
                                               record_spp=2, reps=3, threads=a.threads, workdir=Path(tmp))
            print(f"[{scene}] Embree floor: {floor['floor_samples_per_s']:,.0f} samples/s "
                  f"({floor['rays_per_sample']:.2f} rays per sample)", file=sys.stderr, flush=True)
        results["scenes"][scene] = {"width": w, "height": h, "runs": runs, "median": summ, "floor": floor}
        n, m = summ.get("neepp", {}), summ.get("mitsuba", {})
        # ratio per repetition (the two renders of a rep ran back to back), then the median
        rep_ratios = [x["samples_per_s"] / y["samples_per_s"] for x, y in zip(runs["neepp"], runs["mitsuba"])
                      if x.get("samples_per_s") and y.get("samples_per_s")]
        paired = metrics.paired_ratios(rep_ratios)
        ratio = paired["median"]
        summ["ratio_per_rep"] = rep_ratios
        summ["ratio_summary"] = paired
        msps = lambda v: v / 1e6 if v else None  # noqa: E731
        rows.append({"scene": f"{scene} {w}x{h}", "neepp_sps": msps(n.get("samples_per_s")),
                     "mi_sps": msps(m.get("samples_per_s")), "ratio": ratio,
                     "ratio_range": (f"{min(rep_ratios):.3g}-{max(rep_ratios):.3g}" if len(rep_ratios) > 1 else None),
                     "ratio_geomean": paired["geomean"],
                     "ratio_above_1": (f"{paired['above_1']}/{paired['n']} (p={paired['sign_test_p']:.3g})"
                                       if paired["n"] > 1 else None),
                     "neepp_relmse": n.get("relmse"), "mi_relmse": m.get("relmse"),
                     "neepp_relvar": n.get("relvar"), "mi_relvar": m.get("relvar"),
                     "neepp_mean": n.get("mean_ratio"), "mi_mean": m.get("mean_ratio"),
                     "neepp_mem": n.get("peak_memory_mb"), "mi_mem": m.get("peak_memory_mb"),
                     "neepp_load": n.get("load_time_s"), "mi_load": m.get("load_time_s"),
                     "floor_sps": msps(floor and floor["floor_samples_per_s"]),
                     "ray_share": (n["samples_per_s"] / floor["floor_samples_per_s"]
                                   if floor and n.get("samples_per_s") else None),
                     "floor_ratio": (floor["floor_samples_per_s"] / m["samples_per_s"]
                                     if floor and m.get("samples_per_s") else None)})
        last_img = {k: imgs[-1] for k, imgs in images.items() if imgs}
        if last_img:
            report.comparison_figure(out / f"{scene}_compare.png", last_img, ref,
                                     title=f"{scene} {w}x{h}, {a.spp} spp, max_depth {a.max_depth}",
                                     credit=credit(scene))
            for k, img in last_img.items():
                report.error_map_png(out / f"{scene}_{k}_relmse.png", img, ref)
    results["loadavg_end"] = os.getloadavg()

    headers = {"scene": "scene", "neepp_sps": "neepp M samples/s", "mi_sps": f"Mitsuba {a.variant} M samples/s",
               "ratio": "ratio neepp/Mitsuba", "ratio_range": "ratio range", "ratio_geomean": "ratio geomean",
               "ratio_above_1": "reps neepp faster (sign test p)", "neepp_relmse": "neepp relMSE", "mi_relmse": "Mitsuba relMSE",
               "neepp_relvar": "neepp relVar", "mi_relvar": "Mitsuba relVar",
               "neepp_mean": "neepp mean/ref", "mi_mean": "Mitsuba mean/ref",
               "neepp_mem": "neepp peak MB", "mi_mem": "Mitsuba peak MB",
               "neepp_load": "neepp load s", "mi_load": "Mitsuba load s",
               "floor_sps": "Embree floor M samples/s", "ray_share": "neepp ray share", "floor_ratio": "floor/Mitsuba"}
    table = report.markdown_table(rows, list(headers), headers)
    credits = "".join(f"\n- {scene}: {credit(scene)}" for scene in scenes if credit(scene))
    if credits:
        credits = "\nScene credits:" + credits + "\n"
    md = (f"path, max_depth {a.max_depth}, {a.spp} spp, median of {a.reps} rep(s), "
          f"{results['threads']} threads, load avg {results['loadavg_start'][0]:.2f} -> {results['loadavg_end'][0]:.2f}; "
          f"relMSE against shared/scenes/<scene>/reference (Mitsuba 3.9.1 llvm_ad_rgb, 2272-6032 spp)\n"
          f"machine: {machine.summary(results['machine'])}\n\n{table}\n{FLOOR_NOTE}{credits}")
    (out / "report.md").write_text(md)
    (out / "results.json").write_text(json.dumps(results, indent=2, default=float))
    print(md)
    print(f"wrote {out}/report.md, results.json, *_compare.png", file=sys.stderr)
    return 0


if __name__ == "__main__":
    rc = main()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(rc)
