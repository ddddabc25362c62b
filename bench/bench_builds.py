#!/usr/bin/env python3
"""Two builds of neepp side by side: samples/s of the new build over the baseline's, and whether their
images are the same to the bit. For changes that must not move speed or images (a refactor).

Each scene (default: classroom, bathroom, cornell-box, at the reference's resolution, max_depth 17, as
bench_path.py renders them) is rendered by both binaries in turns (the first to go alternating), `--reps`
times with seeds 0..reps-1; a rep's ratio is new/baseline samples/s from its two runs, summarised by
metrics.paired_ratios (median, geometric mean, sign test). Images of one seed are compared bit for bit.

    .venv/bin/python bench/bench_builds.py --baseline /tmp/base/build/neepp              # build/neepp vs it
    .venv/bin/python bench/bench_builds.py --baseline OLD --new NEW --scenes classroom --spp 16 --reps 5

The machine is shared and noisy: compare ratios from one run only. --threads 1 with --cpu-time reads
each render's CPU time, steadier than wall time under load.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import REFERENCES, SCENES_DIR, machine, metrics, runner  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", required=True, help="the neepp binary to compare against")
    ap.add_argument("--new", default=None, help="the new binary (default: NEEPP_BIN or build/neepp)")
    ap.add_argument("--scenes", default="classroom,bathroom,cornell-box")
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--max-depth", type=int, default=17)
    ap.add_argument("--threads", type=int, default=0, help="0: all cores")
    ap.add_argument("--cpu-time", action="store_true", help="ratios of render_cpu_time_s, not of wall time")
    ap.add_argument("-I", dest="options", action="append", default=[], help="integrator option key=value, for both")
    ap.add_argument("--scenes-dir", default=str(SCENES_DIR))
    ap.add_argument("--json", default=None, help="write the results here")
    a = ap.parse_args(argv)
    new = Path(a.new) if a.new else runner.find_neepp()
    if new is None:
        print("new binary not found (--new, NEEPP_BIN or build/neepp)", file=sys.stderr)
        return 2
    builds = {"new": new, "baseline": Path(a.baseline)}
    options = dict(o.split("=", 1) for o in a.options)
    results = {"machine": machine.describe(), "spp": a.spp, "reps": a.reps, "threads": a.threads,
               "builds": {k: str(v) for k, v in builds.items()}, "scenes": {}}
    rows = []
    with tempfile.TemporaryDirectory(prefix="neepp_builds_") as tmp:
        for scene in a.scenes.split(","):
            w, h, _, _ = REFERENCES[scene]
            xml = Path(a.scenes_dir) / scene / "scene.xml"
            speed = {"new": [], "baseline": []}
            same = True
            for rep in range(a.reps):
                order = ["new", "baseline"] if rep % 2 == 0 else ["baseline", "new"]
                images = {}
                for name in order:
                    r = runner.run_neepp(xml, Path(tmp) / f"{scene}_{name}_{rep}.exr", spp=a.spp, resx=w, resy=h,
                                         max_depth=a.max_depth, seed=rep, threads=a.threads or None, integrator="path",
                                         integrator_args=options or None, binary=builds[name])
                    t = r.stats["render_cpu_time_s"] if a.cpu_time else r.stats["render_time_s"]
                    speed[name].append(w * h * a.spp / t)
                    images[name] = r.image
                same &= bool(np.array_equal(images["new"], images["baseline"]))
                print(f"[{scene}] rep {rep}: new {speed['new'][-1]:,.0f}, baseline {speed['baseline'][-1]:,.0f} "
                      f"samples/s", file=sys.stderr, flush=True)
            ratios = metrics.paired_ratios([n / b for n, b in zip(speed["new"], speed["baseline"])])
            results["scenes"][scene] = {"samples_per_s": speed, "ratio": ratios, "same_images": same}
            rows.append((f"{scene} {w}x{h}", ratios, same))
    print(f"\nsamples/s, new / baseline ({a.spp} spp, {a.reps} reps, interleaved; {'CPU' if a.cpu_time else 'wall'} time)")
    print("| scene | median | geometric mean | reps above 1 | images to the bit |")
    print("|---|---|---|---|---|")
    for name, r, same in rows:
        print(f"| {name} | {r['median']:.3f} | {r['geomean']:.3f} | {r['above_1']} of {r['n']} | {'same' if same else 'DIFFERENT'} |")
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
