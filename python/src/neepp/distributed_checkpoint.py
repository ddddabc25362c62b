"""What a distributed render has summed so far, and its checkpoints (neepp.distributed, --ray --checkpoint).

The driver adds each round's ranges to RoundSums in range order; the image is formed once from those sums.
A checkpoint is RoundSums after a round, with the merged NEE++/integrator state the next round starts
from and where the rounds stand, in the CLI's checkpoint format (written by the same C++ code: a hidden
temporary, flushed, renamed over the file). Resuming puts the sums back and the rounds go on: the same
additions in the same order as an uninterrupted render, so the same image to the bit.
"""
from __future__ import annotations

import json
import os
import signal
from typing import Dict, List, Optional

import numpy as np

from . import _neepp

# Statistics that add up over ranges.
SUMMED = ["rays", "camera_rays", "light_rays", "splats", "shadow_rays", "shadow_rays_occluded",
          "shadow_rays_skipped", "occlusion_time_s", "invalid_samples", "density_lookups",
          "transmittance_lookups", "medium_shadow_rays"]


class RoundSums:
    """The ranges rendered so far, added up in range order (so the same ranges give the same bits however
    they were spread, and however often the driver was restarted between rounds)."""

    def __init__(self):
        self.image_sums: Optional[np.ndarray] = None
        self.splat_sums: Optional[np.ndarray] = None
        self.light_paths = 0.0
        self.ranges: List[List[int]] = []
        self.summed: Dict[str, float] = {key: 0 for key in SUMMED}
        self.passes = 0
        self.first_stats: Optional[dict] = None  # the first range's statistics (its integrator's description)
        self.last_stats: Optional[dict] = None  # the last range's: the statistics' base
        self.worker_render_time_s = 0.0

    @property
    def spp(self) -> int:
        return sum(b - a for a, b in self.ranges)

    def add(self, results: List[dict]) -> None:
        """One round's results (render_range's dicts), added after the ranges before them."""
        for r in sorted(results, key=lambda r: r["first"]):
            if self.ranges and r["first"] != self.ranges[-1][1]:
                raise RuntimeError(f"range [{r['first']}, {r['last']}) does not follow {self.ranges[-1]}")
            if self.image_sums is None:  # zeros, then added: as many ranges are (a -0.0 sum becomes 0.0 alike)
                self.image_sums = np.zeros_like(r["image_sums"])
                self.splat_sums = np.zeros_like(r["splat_sums"])
            self.image_sums += r["image_sums"]
            self.splat_sums += r["splat_sums"]
            self.light_paths += r["light_paths"]
            stats = json.loads(r["stats"])
            for key in SUMMED:
                self.summed[key] += stats.get(key, 0)
            self.passes += stats["passes"]
            self.first_stats = self.first_stats or stats
            self.last_stats = stats
            self.worker_render_time_s += r["wall_s"]
            self.ranges.append([r["first"], r["last"]])

    def driver_json(self, rounds: Dict[str, object]) -> str:
        """What the driver needs beyond the sums to go on (rounds: where its rounds stand)."""
        return json.dumps({"rounds": rounds, "ranges": self.ranges, "summed": self.summed,
                           "first_stats": self.first_stats, "last_stats": self.last_stats,
                           "worker_render_time_s": self.worker_render_time_s})

    @classmethod
    def from_checkpoint(cls, c: dict) -> "RoundSums":
        d = json.loads(c["driver"])
        s = cls()
        s.image_sums = np.array(c["image_sums"], dtype=np.float64)
        s.splat_sums = np.array(c["splat_sums"], dtype=np.int64)
        s.light_paths = c["light_paths"]
        s.ranges = [list(r) for r in d["ranges"]]
        s.summed = d["summed"]
        s.passes = c["passes"]
        s.first_stats, s.last_stats = d["first_stats"], d["last_stats"]
        s.worker_render_time_s = d["worker_render_time_s"]
        if s.spp != c["spp"]:
            raise RuntimeError("the checkpoint's ranges do not add up to its sample count: it is damaged")
        return s


def identity(scene, integrator: str, options: Dict[str, str], seed: int, sampler: str, params: Dict[str, str],
             workers: int, spp: Optional[int]) -> str:
    """What a checkpoint of this render must match: what the CLI's checkpoints hold, and the worker count
    and budget, on which the ranges of the rounds depend."""
    ident = json.loads(_neepp.render_identity(scene, integrator, options, seed, sampler, params))
    ident["distributed"] = {"workers": workers, "budget": f"{spp} spp" if spp is not None else "time"}
    return json.dumps(ident)


def resume(path: str, ident: str) -> dict:
    """The checkpoint at path, if it is this render's (RuntimeError naming what differs otherwise)."""
    c = _neepp.checkpoint_to_resume(path, ident)
    if not c["driver"]:
        raise RuntimeError(f"checkpoint '{path}': no distributed driver's part: it is damaged")
    return c


_saves = [0]  # this process's saves, for the test hook


def save(path: str, ident: str, sums: RoundSums, state: bytes, render_time_s: float, seconds_per_spp: float,
         rounds: Dict[str, object]) -> None:
    """Writes the checkpoint atomically: a hidden temporary beside it, flushed to disk, renamed over it."""
    data = _neepp.checkpoint_bytes(ident, sums.spp, sums.passes, render_time_s, seconds_per_spp,
                                   sums.light_paths, sums.image_sums, sums.splat_sums, state,
                                   sums.driver_json(rounds))
    _saves[0] += 1

    def write(temporary: str) -> None:
        with open(temporary, "wb") as f:
            f.write(data)
        _maybe_die_in_save_for_test(temporary)

    _neepp.write_file_atomically(path, write)


def _maybe_die_in_save_for_test(temporary: str) -> None:
    # Test hook (tests/python/test_distributed_checkpoint.py): the driver kills itself (SIGKILL) in its
    # Nth save, after the temporary is written and before it is renamed: a driver lost mid-save.
    nth = os.environ.get("NEEPP_DISTRIBUTED_KILL_IN_SAVE")
    if nth and _saves[0] == int(nth):
        os.kill(os.getpid(), signal.SIGKILL)


def remove(path: str) -> None:
    """A finished render's checkpoint, and what saves killed half-way left."""
    _neepp.remove_checkpoint(path)
