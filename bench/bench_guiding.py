#!/usr/bin/env python3
"""Path guiding (issue 44, `-I guiding=sdtree`) against plain NEE with the light BVH, as
docs/performance.md measures it: equal spp, one thread, two seeds per configuration; relVar is
metrics.relative_variance of the two seeds' images normalised by the mean of every image of the group
(one reference for all configurations, so their relVars compare); time is render_cpu_time_s (CPU time,
robust to a shared machine); efficiency = 1 / (relVar x CPU time), relative to the first configuration.

    nice .venv/bin/python bench/bench_guiding.py --scene classroom --spp 64 \
        --config nee: --config guided:guiding=sdtree --config ref:form=reference

A configuration is NAME[@BINARY]:k=v,k=v (integrator options, -I; BINARY: another neepp to run). --jobs renders that many at once (each on one
thread); keep it the same for figures that are compared.
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import os
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import metrics, runner  # noqa: E402

SCENES = Path("/work/shared/scenes")


def trimmed_relative_variance(a, b, ref, share: float = 0.01) -> float:
    """relative_variance without the noisiest `share` of the pixels: the bulk of the image, free of the
    few fireflies that make two-seed figures of heavy-tailed estimators jump."""
    a, b, r = (np.asarray(x, dtype=np.float64)[..., :3] for x in (a, b, ref))
    px = np.sort((((a - b) ** 2) / (r * r + metrics.EPS)).mean(-1).ravel() / 2)
    return float(px[: int(len(px) * (1 - share))].mean())


def parse_config(text: str) -> tuple[str, dict, str | None]:
    name, _, opts = text.partition(":")
    name, _, binary = name.partition("@")
    args = dict(kv.split("=", 1) for kv in opts.split(",") if kv)
    return name, args, binary or None


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", default="classroom")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--resx", type=int, default=320)
    p.add_argument("--resy", type=int, default=180)
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    p.add_argument("--config", action="append", required=True)
    p.add_argument("--jobs", type=int, default=1)
    p.add_argument("--binary", default=None, help="the neepp to run (default: $NEEPP_BIN or build/neepp)")
    p.add_argument("--out", default=str(REPO / "bench" / "out" / "guiding"))
    a = p.parse_args()
    xml = SCENES / a.scene / "scene.xml"
    if not xml.exists():
        xml = REPO / "scenes" / a.scene / "scene.xml"
    configs = [parse_config(c) for c in a.config]
    print("machine:", os.popen("uptime").read().strip(), flush=True)
    # --scene is a folder of the shared scenes or a path to a scene's folder: its name names the output.
    out = Path(a.out) / f"{Path(a.scene).name}_{a.resx}x{a.resy}_{a.spp}"

    def one(name, args, binary, seed):
        return runner.run_neepp(xml, out / f"{name}_{seed}.exr", spp=a.spp, seed=seed, threads=1, resx=a.resx,
                                resy=a.resy, integrator_args=args, binary=binary or a.binary)

    jobs = {}
    with cf.ThreadPoolExecutor(a.jobs) as pool:
        for name, args, binary in configs:
            for seed in a.seeds:
                jobs[(name, seed)] = pool.submit(one, name, args, binary, seed)
    res = {k: f.result() for k, f in jobs.items()}
    ref = np.mean([np.asarray(r.image, dtype=np.float64) for r in res.values()], axis=0)
    rows = []
    for name, _, _ in configs:
        imgs = [res[(name, s)].image for s in a.seeds]
        rv = np.mean([metrics.relative_variance(imgs[i], imgs[i + 1], ref) for i in range(0, len(imgs) - 1, 2)])
        trimmed = np.mean([trimmed_relative_variance(imgs[i], imgs[i + 1], ref) for i in range(0, len(imgs) - 1, 2)])
        cpu = np.mean([res[(name, s)].stats["render_cpu_time_s"] for s in a.seeds])
        rows.append((name, float(rv), float(cpu), 1 / (rv * cpu), res[(name, a.seeds[0])].stats, float(trimmed)))
    base = rows[0]
    print(f"\n{a.scene} {a.resx}x{a.resy}, {a.spp} spp, seeds {a.seeds}")
    print("| configuration | relVar | CPU s | relVar / first | CPU / first | efficiency / first | trimmed relVar / first |")
    print("|---|---|---|---|---|---|---|")
    for name, rv, cpu, eff, _, tr in rows:
        print(f"| {name} | {rv:.4g} | {cpu:.2f} | {rv / base[1]:.2f} | {cpu / base[2]:.2f} | {eff / base[3]:.2f} | {tr / base[5]:.2f} |")
    print("machine after:", os.popen("uptime").read().strip())
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps(
        {"args": vars(a), "rows": [{"name": n, "rel_var": rv, "cpu_s": c, "efficiency": e,
                                    "guiding": s.get("integrator_statistics", s).get("guiding") if isinstance(s, dict) else None}
                                   for n, rv, c, e, s, _ in rows]}, indent=1, default=str))


if __name__ == "__main__":
    main()
