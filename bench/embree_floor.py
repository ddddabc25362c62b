#!/usr/bin/env python3
"""The Embree floor: what a render's ray queries cost alone, and how much of its time is the rest.

A path tracer's samples/s is bounded by its ray queries, whatever its shading costs. For each scene this
script renders with neepp `path` as bench_path.py does (reference resolution, max_depth 17), then renders
again at a few spp with the ray recorder preloaded (bench/ray_replay/recorder.cpp: every Embree call's
rays and outcomes, per thread, in order), and traces those rays again with nothing but Embree
(neepp_ray_replay: same scene build, same packets, one thread per recorded thread, every outcome checked
against the render's). The table gives:

- rays per sample (intersections and shadow rays), from the recorded render;
- Embree alone: M rays/s over all threads and ns per ray per thread, as the render's packets and one ray
  at a time (rtcIntersect1/rtcOccluded1);
- the floor: samples/s if a sample cost only its rays at that speed (packets), i.e. the ceiling of any
  shading work;
- ray share: the render's samples/s over the floor, the part of the render's time that its ray queries
  would take alone. 1 - share is what shading, sampling and bookkeeping cost; at a share of 0.5, shading
  costs as much as the rays.

With --mitsuba, Mitsuba 3's samples/s at the same settings is measured too, and the floor over it is the
largest neepp/Mitsuba ratio reachable without tracing fewer or cheaper rays.

    .venv/bin/python bench/embree_floor.py                          # classroom + bathroom, ~3 min
    .venv/bin/python bench/embree_floor.py --scenes bathroom --mitsuba --reps 3

Writes bench/out/embree_floor/ (git-ignored): report.md, results.json. The machine is shared and noisy:
timed parts are repeated (--reps) and medians reported; the replay runs all its reps in one process.
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import REFERENCES, SCENES_DIR, machine, report, runner  # noqa: E402


def tools_beside(binary: Path) -> tuple[Path, Path]:
    """The recorder library and the replay tool, built beside the neepp binary."""
    return binary.parent / "libneepp_ray_recorder.so", binary.parent / "neepp_ray_replay"


def replay(replay_bin: Path, scene: Path, defines: dict, files: list[Path], reps: int) -> dict:
    cmd = [str(replay_bin), str(scene), "--reps", str(reps)]
    for k, v in defines.items():
        cmd += ["-D", f"{k}={v}"]
    cmd += [str(f) for f in files]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"replay failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr[-3000:]}")
    return json.loads(r.stdout)


def ray_floor(scene: Path, defines: dict, binary: Path, *, record_spp: int, reps: int, threads: int = 0,
              workdir: Path) -> dict:
    """Records a render at record_spp (defines give resx and resy) and replays its rays: rays per sample,
    Embree's rays/s alone (packets, single) and the floor in samples/s. Checks the recording is complete
    and every replayed outcome matches the render's."""
    samples = int(defines["resx"]) * int(defines["resy"]) * record_spp
    recorder, replay_bin = tools_beside(binary)
    rec_dir = workdir / "rays"
    rec_dir.mkdir(parents=True, exist_ok=True)
    rec = runner.run_neepp(scene, workdir / "recorded.exr", spp=record_spp, threads=threads, defines=defines,
                           binary=binary, env={"LD_PRELOAD": str(recorder), "NEEPP_RAY_RECORD_DIR": str(rec_dir)})
    files = sorted(rec_dir.glob("rays.*.bin"))
    if not files:
        raise SystemExit(f"the recorder wrote nothing under {rec_dir}: was {recorder} preloaded?")
    rp = replay(replay_bin, scene, defines, files, reps)
    st = rec.stats
    if rp["intersect_rays"] != st["rays"] or rp["occluded_rays"] != st["shadow_rays"]:
        raise SystemExit(f"{scene}: recorded {rp['intersect_rays']} + {rp['occluded_rays']} rays, the render "
                         f"counted {st['rays']} + {st['shadow_rays']}: the recording is incomplete")
    for mode in ("packets", "single"):
        if rp[mode]["mismatches"]:
            raise SystemExit(f"{scene}: replay ({mode}) disagrees with the render on {rp[mode]['mismatches']} rays")
    rays = rp["intersect_rays"] + rp["occluded_rays"]
    out = {"record_spp": record_spp, "intersect_per_sample": rp["intersect_rays"] / samples,
           "shadow_per_sample": rp["occluded_rays"] / samples, "rays_per_sample": rays / samples,
           "replay_threads": rp["threads"], "packet_width": rp["packet_width"]}
    for mode in ("packets", "single"):
        secs = statistics.median(rp[mode]["seconds"])
        out[mode] = {"seconds": rp[mode]["seconds"], "rays_per_s": rays / secs,
                     "ns_per_ray_per_thread": secs * rp["threads"] / rays * 1e9}
    out["floor_samples_per_s"] = out["packets"]["rays_per_s"] / out["rays_per_sample"]
    return out


def measure(scene_name: str, scene: Path, res: tuple[int, int], a, binary: Path) -> dict:
    w, h = res
    defines = {"resx": w, "resy": h, "max_depth": a.max_depth}
    timed, mitsuba = [], []
    with tempfile.TemporaryDirectory(prefix="neepp_floor_") as tmp:
        tmp = Path(tmp)
        for rep in range(a.reps):
            r = runner.run_neepp(scene, tmp / "timed.exr", spp=a.spp, seed=rep, threads=a.threads,
                                 defines=defines, binary=binary)
            timed.append(r.stats["samples_per_s"])
            print(f"[{scene_name}] render rep {rep}: {timed[-1]:,.0f} samples/s", flush=True)
        floor = ray_floor(scene, defines, binary, record_spp=a.record_spp, reps=a.reps, threads=a.threads,
                          workdir=tmp)
        for rep in range(a.reps if a.mitsuba else 0):
            r = runner.run_mitsuba(scene, tmp / "mitsuba.exr", resx=w, resy=h, spp=a.spp, max_depth=a.max_depth,
                                   seed=rep, threads=a.threads)
            mitsuba.append(r.stats["samples_per_s"])
            print(f"[{scene_name}] mitsuba rep {rep}: {mitsuba[-1]:,.0f} samples/s", flush=True)
    out = {"scene": scene_name, "resolution": [w, h], "spp": a.spp, "render_samples_per_s": statistics.median(timed),
           "render_runs": timed, **floor}
    out["ray_share"] = out["render_samples_per_s"] / out["floor_samples_per_s"]
    if mitsuba:
        out["mitsuba_samples_per_s"] = statistics.median(mitsuba)
        out["mitsuba_runs"] = mitsuba
        out["floor_over_mitsuba"] = out["floor_samples_per_s"] / out["mitsuba_samples_per_s"]
        out["render_over_mitsuba"] = out["render_samples_per_s"] / out["mitsuba_samples_per_s"]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default="classroom,bathroom", help="comma-separated scene names")
    ap.add_argument("--spp", type=int, default=16, help="spp of the timed renders")
    ap.add_argument("--record-spp", type=int, default=2, help="spp of the recorded render (~80 MB per spp "
                    "at 512x512 on bathroom)")
    ap.add_argument("--reps", type=int, default=3, help="timed renders, and replays of each kind")
    ap.add_argument("--max-depth", type=int, default=17)
    ap.add_argument("--threads", type=int, default=0, help="render threads (0: all); the replay uses as many")
    ap.add_argument("--res", default=None, help="WxH instead of each scene's reference resolution")
    ap.add_argument("--mitsuba", action="store_true", help="also time Mitsuba 3 llvm at the same settings")
    ap.add_argument("--scenes-dir", default=str(SCENES_DIR))
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "embree_floor"))
    a = ap.parse_args(argv)
    binary = runner.find_neepp()
    if binary is None:
        print("neepp binary not found (NEEPP_BIN or build/neepp)", file=sys.stderr)
        return 2
    missing = [p for p in tools_beside(binary) if not p.exists()]
    if missing:
        print(f"not built beside {binary}: {', '.join(map(str, missing))}", file=sys.stderr)
        return 2
    results = []
    for name in [s.strip() for s in a.scenes.split(",") if s.strip()]:
        scene = Path(a.scenes_dir) / name / "scene.xml"
        if not scene.exists():
            scene = Path(name)
        if not scene.exists():
            print(f"scene not found: {name}", file=sys.stderr)
            return 2
        if a.res:
            res = tuple(int(x) for x in a.res.lower().split("x"))
        elif name in REFERENCES:
            res = REFERENCES[name][:2]
        else:
            ap.error(f"{name}: give --res (no reference resolution known)")
        results.append(measure(name, scene, res, a, binary))

    rows = []
    for r in results:
        row = {"scene": f"{r['scene']} {r['resolution'][0]}x{r['resolution'][1]}",
               "rays/sample": f"{r['intersect_per_sample']:.2f} + {r['shadow_per_sample']:.2f}",
               "Embree M rays/s (packets / single)":
                   f"{r['packets']['rays_per_s'] / 1e6:.2f} / {r['single']['rays_per_s'] / 1e6:.2f}",
               "ns/ray/thread": f"{r['packets']['ns_per_ray_per_thread']:.0f} / {r['single']['ns_per_ray_per_thread']:.0f}",
               "floor M samples/s": f"{r['floor_samples_per_s'] / 1e6:.3f}",
               "render M samples/s": f"{r['render_samples_per_s'] / 1e6:.3f}",
               "ray share": f"{r['ray_share']:.2f}"}
        if a.mitsuba:
            row |= {"Mitsuba M samples/s": f"{r['mitsuba_samples_per_s'] / 1e6:.3f}",
                    "render / Mitsuba": f"{r['render_over_mitsuba']:.2f}",
                    "floor / Mitsuba": f"{r['floor_over_mitsuba']:.2f}"}
        rows.append(row)
    md = (f"# Embree floor: neepp path, max_depth {a.max_depth}, {a.spp} spp timed, {a.record_spp} spp recorded\n\n"
          f"machine: {machine.summary()}; binary {binary}\n\n" + report.markdown_table(rows) + "\n\n"
          "rays/sample: intersections + shadow rays. Embree alone: the recorded rays traced again with nothing "
          "else running (medians of the reps). floor: samples/s if a sample cost only its rays (packets). "
          "ray share: render / floor.\n")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.md").write_text(md)
    (out / "results.json").write_text(json.dumps({"machine": machine.describe(), "results": results}, indent=2))
    print("\n" + md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
