"""Checkpoints of distributed renders (neepp.distributed, `neepp render --ray --checkpoint S`, `--resume`): a
driver stopped after any round resumes to the image, to the bit, of an uninterrupted render; a driver killed
(SIGKILL) at random moments on a Ray cluster, once in the middle of a save, is resumed to the uninterrupted
render's file, byte for byte, with no temporary left; a checkpoint of another render, or of a render on one
machine, is refused, and the other way round."""
from __future__ import annotations

import glob
import json
import os
import random
import signal
import subprocess
import time

import numpy as np
import pytest

import neepp
import neepp.distributed as nd

ray = pytest.importorskip("ray", reason="Ray is installed by scripts/setup_python.sh")

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEMO = os.path.join(REPO, "scenes", "door-ajar", "scene.xml")
SMALL = {"resx": 48, "resy": 32}
CLI = os.path.join(os.path.dirname(neepp.__file__), "bin", "neepp")  # the package's CLI: the same build


class _StopAt:
    """on_checkpoint that stops the render (as Ctrl-C does) at its nth save."""

    def __init__(self, nth):
        self.nth, self.seen = nth, 0

    def __call__(self, image):
        self.seen += 1
        assert image.shape == (32, 48, 3)
        if self.seen == self.nth:
            raise KeyboardInterrupt


@pytest.mark.parametrize("integrator,options,spp", [("path", {"shadow_rays": "neepp-adaptive"}, 16),
                                                    ("bdpt", {"light_paths": "neepp"}, 6),  # splats, BDPT's pool
                                                    ("path", {}, 5)])  # nothing learned: two rounds
def test_a_render_stopped_after_any_round_resumes_to_the_same_bits(tmp_path, integrator, options, spp):
    # In this process (local=True: the ranges a cluster renders, to the same bits), stopped at each save.
    common = dict(spp=spp, workers=2, integrator=integrator, options=options, seed=3, local=True, **SMALL)
    ref, ref_stats = nd.render(DEMO, **common)
    rounds = ref_stats["distributed"]["rounds"]
    checkpoint = str(tmp_path / "a.exr.checkpoint")
    for stop in range(1, rounds):  # a save after each round but the last (the finished render needs none)
        if os.path.exists(checkpoint):
            os.remove(checkpoint)
        with pytest.raises(KeyboardInterrupt):
            nd.render(DEMO, checkpoint=checkpoint, checkpoint_every=0, on_checkpoint=_StopAt(stop), **common)
        img, stats = nd.render(DEMO, checkpoint=checkpoint, resume=True, **common)
        assert np.array_equal(img, ref), f"stopped at save {stop} of {rounds - 1}"
        assert 1 <= stats["resumed_spp"] < spp and stats["spp"] == spp
        assert stats["distributed"]["ranges"] == ref_stats["distributed"]["ranges"]
        assert stats["distributed"]["rounds"] == rounds
        for key in ("rays", "shadow_rays", "shadow_rays_skipped", "splats", "passes"):
            assert stats[key] == ref_stats[key], key
    assert not glob.glob(str(tmp_path / ".*.tmp"))


def test_another_render_and_a_single_machine_checkpoint_are_refused(tmp_path):
    checkpoint = str(tmp_path / "a.exr.checkpoint")
    common = dict(spp=8, workers=2, options={"shadow_rays": "neepp"}, seed=3, local=True, **SMALL)
    with pytest.raises(KeyboardInterrupt):
        nd.render(DEMO, checkpoint=checkpoint, checkpoint_every=0, on_checkpoint=_StopAt(2), **common)
    for change, expect in [({"workers": 3}, '"workers":2'), ({"seed": 4}, "its seed is 3"),
                           ({"spp": 9}, '"budget":"8 spp"'), ({"resx": 40}, 'its film is "48x32"'),
                           ({"options": {"shadow_rays": "nee"}}, "its integrator is")]:
        with pytest.raises(RuntimeError, match="of another render") as e:
            nd.render(DEMO, checkpoint=checkpoint, resume=True, **{**common, **change})
        assert expect in str(e.value), (change, str(e.value))
    with pytest.raises(RuntimeError, match="no checkpoint"):
        nd.render(DEMO, checkpoint=str(tmp_path / "none"), resume=True, **common)
    # The two kinds of checkpoint, each resumed as the other: refused, saying which command resumes it.
    out = tmp_path / "one.exr"
    args = [DEMO, "-o", str(out), "--seed", "3", "-D", "resx=48", "-D", "resy=32", "-q"]
    r = subprocess.run([CLI, "render", *args, "--time", "0.3", "--checkpoint", "100"], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0 and os.path.exists(f"{out}.checkpoint"), r.stderr  # a time limit keeps it
    r = subprocess.run([CLI, "render", *args, "--spp", "8", "--resume", "--ray", "--workers", "2"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and "of a render on one machine" in r.stderr and "without --ray" in r.stderr, r.stderr
    os.replace(checkpoint, f"{out}.checkpoint")
    r = subprocess.run([CLI, "render", *args, "--spp", "8", "--resume"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and "of a distributed render" in r.stderr and "--ray --workers 2" in r.stderr, r.stderr


@pytest.fixture(scope="module")
def cluster():
    """A local Ray instance (loopback only) started by this process, so that it outlives the drivers killed
    here (a driver that starts its own and is killed leaves some of its processes behind); the drivers
    connect to it by address."""
    if ray.is_initialized():
        ray.shutdown()
    nd._Ray(None, 2, 1)
    try:
        yield ray.get_runtime_context().gcs_address
    finally:
        ray.shutdown()


def test_a_driver_killed_at_random_moments_resumes_to_the_same_file(cluster, tmp_path):
    seed = int(os.environ.get("NEEPP_TEST_SEED", random.randrange(1 << 30)))
    rng = random.Random(seed)
    common = [DEMO, "--spp", "64", "--seed", "4", "-D", "resx=48", "-D", "resy=32", "-q", "--ray", cluster,
              "--workers", "2", "-I", "shadow_rays=neepp-adaptive", "--stats"]
    env = dict(os.environ, RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER="0")  # the drivers' end on the loopback too
    r = subprocess.run([CLI, "render", *common, str(tmp_path / "ref.json"), "-o", str(tmp_path / "ref.exr")],
                       env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "out.exr"
    checkpoint = f"{out}.checkpoint"
    run = [CLI, "render", *common, str(tmp_path / "out.json"), "-o", str(out), "--checkpoint", "0.001"]

    def resume():
        return ["--resume"] if os.path.exists(checkpoint) else []

    # Killed in its second save (after the temporary is written, before its rename): the first save stays.
    r = subprocess.run(run, env=dict(env, NEEPP_DISTRIBUTED_KILL_IN_SAVE="2"), capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == -signal.SIGKILL, r.stderr
    assert glob.glob(str(tmp_path / ".out.exr.checkpoint.*.tmp")), "the kill missed the save"
    assert os.path.exists(checkpoint)  # the first save's
    # Killed at random moments, each run resuming the last: once while it starts, then each at a random
    # moment after its first save (so that it is rendering: in a round, a merge or a save); the third is
    # stopped by SIGTERM instead, which saves the rounds completed and exits.
    kills = []
    for i in range(4):
        saved_at = os.stat(checkpoint).st_mtime_ns
        p = subprocess.Popen(run + resume(), env=env, stderr=subprocess.PIPE, text=True)
        if i > 0:
            while p.poll() is None and os.path.exists(checkpoint) and os.stat(checkpoint).st_mtime_ns == saved_at:
                time.sleep(0.005)
        delay = rng.uniform(0.1, 1.0) if i == 0 else rng.uniform(0, 0.4)
        sig = signal.SIGTERM if i == 2 else signal.SIGKILL
        try:
            p.wait(timeout=delay)
        except subprocess.TimeoutExpired:
            p.send_signal(sig)
            p.wait(timeout=60)
            kills.append(round(delay, 2))
        if p.returncode == 0:
            break
        if sig == signal.SIGTERM:
            err = p.stderr.read()
            assert p.returncode == 143 and "--resume continues it" in err, err
        else:
            assert p.returncode == -signal.SIGKILL, p.stderr.read()
    if os.path.exists(checkpoint):
        r = subprocess.run(run + ["--resume"], env=env, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
    what = f"test seed {seed}, killed {kills} s after start-up, then after a save"
    assert out.read_bytes() == (tmp_path / "ref.exr").read_bytes(), what
    assert (tmp_path / "out.png").read_bytes() == (tmp_path / "ref.png").read_bytes(), what
    stats, ref = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("out", "ref"))
    assert stats["resumed_spp"] >= 1 and stats["spp"] == 64 and stats["shadow_rays_skipped"] > 0, what
    for key in ("rays", "shadow_rays", "shadow_rays_skipped", "passes"):
        assert stats[key] == ref[key], (key, what)
    assert stats["distributed"]["ranges"] == ref["distributed"]["ranges"]
    assert not os.path.exists(checkpoint)  # a finished render needs it no more
    assert not glob.glob(str(tmp_path / ".*.tmp")), what  # nor what the killed saves left

