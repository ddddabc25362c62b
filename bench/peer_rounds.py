"""Rounds of neepp against a peer renderer, and their summary: what tungsten_peer.py and pbrt_peer.py share.

A round renders the same scene with both renderers, taking turns to go first (neepp first in even rounds),
each render inside a LoadMeter; a round that others disturbed (more than args.max_other_load cores) is
rendered again with another seed, up to args.retries times, and the least disturbed attempt is kept.
"""
from __future__ import annotations

import json
import math
import os
import resource
import statistics
import time
from pathlib import Path
from typing import Callable

import numpy as np

from neepp_tools import REFERENCES, exr, metrics

LUMA = np.array([0.2126, 0.7152, 0.0722])


# ----------------------------------------------------------------------------------------------
# machine load around a child process


def _cpu_busy_s() -> float:
    """Machine-wide busy CPU seconds since boot (/proc/stat)."""
    with open("/proc/stat") as f:
        v = [int(x) for x in f.readline().split()[1:]]
    user, nice, system, idle, iowait, irq, softirq, steal = (v + [0] * 8)[:8]
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def _children_cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def wait_quiet(max_cores: float, limit_s: float, window_s: float = 2.0) -> float:
    """Wait until the machine's busy CPU over window_s is under max_cores (at most limit_s); seconds waited."""
    t0 = time.perf_counter()
    while True:
        b0, w0 = _cpu_busy_s(), time.perf_counter()
        time.sleep(window_s)
        busy = (_cpu_busy_s() - b0) / (time.perf_counter() - w0)
        waited = time.perf_counter() - t0
        if busy < max_cores or waited >= limit_s:
            return waited
        time.sleep(5.0)


class LoadMeter:
    """CPU time used by others than this process's waited-for children during a with-block, in cores."""

    def __enter__(self):
        self.t0, self.busy0, self.child0 = time.perf_counter(), _cpu_busy_s(), _children_cpu_s()
        self.loadavg0 = os.getloadavg()[0]
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self.t0
        self.child_cpu = _children_cpu_s() - self.child0
        busy = _cpu_busy_s() - self.busy0
        self.other_cores = max(0.0, (busy - self.child_cpu) / max(self.wall, 1e-9))
        self.loadavg1 = os.getloadavg()[0]
        return False

    def summary(self) -> dict:
        return {"other_load_cores": self.other_cores, "child_cpu_s": self.child_cpu, "process_wall_s": self.wall,
                "loadavg_1min_before": self.loadavg0, "loadavg_1min_after": self.loadavg1}


# ----------------------------------------------------------------------------------------------
# images


def channel_means(img: np.ndarray) -> list[float]:
    return [float(x) for x in np.asarray(img, dtype=np.float64).reshape(-1, 3).mean(axis=0)]


def luminance(means: list[float]) -> float:
    return float(np.dot(LUMA, means))


# ----------------------------------------------------------------------------------------------
# rounds and their summary




def run_rounds(args, scene: str, pair: str, peer: str, pixels: int, spp: int,
               render: Callable[[str, int, int], dict]) -> tuple[list, list]:
    """args.rounds rounds; render(who, round, seed) -> {"image", "render_time_s", "wall_s", ...} for who in
    ("neepp", peer). Returns the kept rounds, (record, neepp image, peer image) each, and every attempt's
    record (ratio = neepp samples/s over the peer's, cpu_ratio the same per CPU second of the render)."""
    rounds, attempts = [], []
    for r in range(args.rounds):
        best = None
        for attempt in range(args.retries + 1):
            seed = args.seed + 1000 * r + 100 * attempt
            order = ["neepp", peer] if r % 2 == 0 else [peer, "neepp"]
            runs = {}
            for who in order:
                if args.wait_quiet > 0:
                    wait_quiet(args.max_other_load, args.wait_quiet)
                with LoadMeter() as lm:
                    q = render(who, r, seed)
                runs[who] = {**q, **lm.summary()}
            for q in runs.values():
                q["samples_per_s"] = pixels * spp / q["render_time_s"]
                # CPU time of the render itself: the process's, less its loading (taken as one busy thread);
                # samples per CPU second do not depend on how many cores others left free.
                q["render_cpu_s"] = max(1e-9, q["child_cpu_s"] - max(0.0, q["process_wall_s"] - q["render_time_s"]))
                q["samples_per_cpu_s"] = pixels * spp / q["render_cpu_s"]
                if q["render_cpu_s"] < 0.1 * q["render_time_s"]:  # loading estimate failed (a tiny render)
                    q["samples_per_cpu_s"] = float("nan")
            worst = max(q["other_load_cores"] for q in runs.values())
            rec = {"round": r, "attempt": attempt, "seed": seed, "order": order,
                   **{f"{k}_{q}": runs[k][q] for k in runs for q in ("render_time_s", "samples_per_s", "wall_s",
                                                                     "other_load_cores", "loadavg_1min_before",
                                                                     "render_cpu_s", "samples_per_cpu_s")}}
            rec["ratio"] = runs["neepp"]["samples_per_s"] / runs[peer]["samples_per_s"]
            rec["cpu_ratio"] = runs["neepp"]["samples_per_cpu_s"] / runs[peer]["samples_per_cpu_s"]
            attempts.append(rec)
            print(json.dumps({"scene": scene, "pair": pair, **rec}), flush=True)
            rec["loaded"] = worst > args.max_other_load
            if best is None or worst < best[0]:  # keep the least disturbed attempt
                best = (worst, rec, runs["neepp"]["image"], runs[peer]["image"])
            if worst <= args.max_other_load:
                break
        rounds.append(best[1:])
    return rounds, attempts


def summarize_rounds(args, scene: str, peer: str, rounds: list, w: int, h: int) -> tuple[dict, np.ndarray,
                                                                                          np.ndarray, np.ndarray | None]:
    """The table's columns both scripts give: render times and samples/s (medians), the paired ratios, image
    means (luminance, its standard error from the rounds' spread, RGB) against the Mitsuba reference, relMSE
    against the reference box-downsampled to w x h (median over rounds) and the efficiency ratio. Returns
    them with both mean images and the downsampled reference (None if the sizes do not divide)."""
    recs = [x[0] for x in rounds]
    img_n = np.mean([x[1] for x in rounds], axis=0)
    img_p = np.mean([x[2] for x in rounds], axis=0)
    per_round = {k: [channel_means(x[i]) for x in rounds] for k, i in (("neepp", 1), (peer, 2))}
    ref = exr.read_exr(Path(args.scenes_dir) / scene / "reference" / REFERENCES[scene][3])
    mean_n, mean_p, mean_r = channel_means(img_n), channel_means(img_p), channel_means(ref)

    def lum_err(k):  # standard error of the luminance mean from the rounds' spread
        lums = [luminance(m) for m in per_round[k]]
        return statistics.stdev(lums) / math.sqrt(len(lums)) if len(lums) > 1 else float("nan")

    f = ref.shape[1] // w
    ref_small = metrics.downsample(ref, f) if f >= 1 and ref.shape[1] == w * f and ref.shape[0] == h * f else None
    relmse = {k: (statistics.median(metrics.relmse(x[i], ref_small) for x in rounds) if ref_small is not None
                  else float("nan")) for k, i in (("neepp", 1), (peer, 2))}
    ratios = metrics.paired_ratios([x["ratio"] for x in recs])
    t_n = statistics.median(x["neepp_render_time_s"] for x in recs)
    t_p = statistics.median(x[f"{peer}_render_time_s"] for x in recs)
    row = {"neepp s": t_n, f"{peer} s": t_p,
           "neepp samples/s": statistics.median(x["neepp_samples_per_s"] for x in recs),
           f"{peer} samples/s": statistics.median(x[f"{peer}_samples_per_s"] for x in recs),
           "ratio (median)": ratios["median"], "ratio min": min(x["ratio"] for x in recs),
           "ratio max": max(x["ratio"] for x in recs),
           "cpu-time ratio (median)": statistics.median(x["cpu_ratio"] for x in recs),
           "neepp Y": luminance(mean_n), "neepp Y stderr": lum_err("neepp"),
           f"{peer} Y": luminance(mean_p), f"{peer} Y stderr": lum_err(peer), "ref Y": luminance(mean_r),
           "neepp/ref": luminance(mean_n) / luminance(mean_r), f"{peer}/ref": luminance(mean_p) / luminance(mean_r),
           "neepp RGB": mean_n, f"{peer} RGB": mean_p, "ref RGB": mean_r,
           "neepp relMSE": relmse["neepp"], f"{peer} relMSE": relmse[peer],
           "efficiency ratio": (relmse[peer] * t_p) / (relmse["neepp"] * t_n),
           "max other load (cores)": max(max(x["neepp_other_load_cores"], x[f"{peer}_other_load_cores"])
                                         for x in recs),
           "ratios": ratios, "rounds_detail": recs}
    return row, img_n, img_p, ref_small
