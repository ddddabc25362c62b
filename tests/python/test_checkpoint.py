"""--checkpoint and --resume as a user meets them: a render killed (SIGKILL, so no handler runs) or
stopped (SIGTERM) after writing checkpoints is resumed to exactly the image an uninterrupted render
gives; a checkpoint of another render is refused, naming what differs."""
from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from neepp_tools.exr import read_exr

REPO = Path(__file__).resolve().parents[2]
DEMO = REPO / "scenes" / "door-ajar" / "scene.xml"


OFFICE = REPO / "scenes" / "office" / "scene.xml"  # many lights: a learning light sampler has something to learn


def args(neepp_bin, out, spp, *extra, scene=DEMO):
    return [str(neepp_bin), "render", str(scene), "-o", str(out), "--spp", str(spp), "--seed", "5", "--quiet",
            "-D", "resx=160", "-D", "resy=90", *map(str, extra)]


def wait_for(path: Path, timeout: float):
    t0 = time.time()
    while not path.exists():
        assert time.time() - t0 < timeout, f"{path} never appeared"
        time.sleep(0.05)


_uninterrupted: dict = {}


def uninterrupted(neepp_bin, tmp_path, spp, *extra, scene=DEMO):
    """The image and statistics of the render run through without a stop: rendered once per set of arguments
    in this module (the path SIGKILL and SIGTERM cases share theirs, as do the learning light sampler's two),
    since a render is the same to the bit for the same arguments and thread count."""
    key = (spp, tuple(map(str, extra)), str(scene))
    if key not in _uninterrupted:
        ref = tmp_path / "ref.exr"
        subprocess.run(args(neepp_bin, ref, spp, *extra, "--stats", tmp_path / "ref.json", scene=scene), check=True,
                       timeout=300)
        _uninterrupted[key] = read_exr(ref), json.loads((tmp_path / "ref.json").read_text())
    return _uninterrupted[key]


@pytest.mark.parametrize("integrator, spp, sig, options", [
    ("path", 300, signal.SIGKILL, []),
    ("bdpt", 100, signal.SIGKILL, []),  # passes of 1, 32, 32, 32, 3 spp: the kill lands inside the third
    ("path", 300, signal.SIGTERM, []),
    ("path", 200, signal.SIGKILL, ["-I", "shadow_rays=neepp-adaptive"]),  # the map and the calibration resume
    ("pssmlt", 40, signal.SIGKILL, []),  # the chains resume where the last complete pass left them
    ("pssmlt", 40, signal.SIGTERM, ["-I", "shadow_rays=neepp"]),  # a pass cut short: its mutations are undone
])
def test_a_stopped_render_resumes_to_the_uninterrupted_image(neepp_bin, tmp_path, integrator, spp, sig, options):
    out = tmp_path / "out.exr"
    ref_image, ref_stats = uninterrupted(neepp_bin, tmp_path, spp, "--integrator", integrator, *options)
    checkpoint = Path(str(out) + ".checkpoint")
    p = subprocess.Popen(args(neepp_bin, out, spp, "--integrator", integrator, *options, "--checkpoint", 0.2,
                              "--stats", tmp_path / "first.json"))
    wait_for(checkpoint, 120)
    time.sleep(0.5)
    p.send_signal(sig)
    p.wait(timeout=60)
    assert p.returncode == (143 if sig == signal.SIGTERM else -9)
    assert checkpoint.exists() and out.exists()  # the image so far is written with each checkpoint
    r = subprocess.run(args(neepp_bin, out, spp, "--integrator", integrator, *options, "--resume", "--stats",
                            tmp_path / "s.json"), capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    assert 1 <= s["resumed_spp"] < spp and s["spp"] == spp and s["stopped_by"] == "spp"
    if sig == signal.SIGTERM:  # stopped cleanly: its last checkpoint is where it stopped
        assert s["resumed_spp"] == json.loads((tmp_path / "first.json").read_text())["spp"]
    assert np.array_equal(read_exr(out), ref_image)
    # The counters continue too: a pass cut short by the stop is in neither the image nor the counts.
    for key in ("rays", "shadow_rays", "light_rays", "splats"):
        assert s[key] == ref_stats[key], key
    assert not checkpoint.exists()  # a finished render needs it no more


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_a_learning_light_sampler_resumes_to_the_uninterrupted_image(neepp_bin, tmp_path, sig):
    """light_sampler=bayes learns from NEE's samples between passes: its statistics travel in the checkpoint."""
    opts, spp = ["-I", "light_sampler=bayes"], 96
    out = tmp_path / "out.exr"
    ref_image, ref_stats = uninterrupted(neepp_bin, tmp_path, spp, *opts, scene=OFFICE)
    learned = ref_stats["integrator_statistics"]["light_sampler"]
    assert learned["used"] == "bayes" and learned["samples_learned"] > 0 and learned["passes"] > 2
    checkpoint = Path(str(out) + ".checkpoint")
    p = subprocess.Popen(args(neepp_bin, out, spp, *opts, "--checkpoint", 0.2, scene=OFFICE))
    wait_for(checkpoint, 120)
    time.sleep(0.5)
    p.send_signal(sig)
    p.wait(timeout=60)
    r = subprocess.run(args(neepp_bin, out, spp, *opts, "--resume", "--stats", tmp_path / "s.json", scene=OFFICE),
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    assert 1 <= s["resumed_spp"] < spp and s["spp"] == spp
    assert np.array_equal(read_exr(out), ref_image)


@pytest.mark.parametrize("change, expect", [(["--seed", "6"], "its seed is 5"),
                                            (["-D", "resx=80"], 'its film is "160x90"'),
                                            (["--integrator", "light"], "integrator")])
def test_a_checkpoint_of_another_render_is_refused(neepp_bin, tmp_path, change, expect):
    out = tmp_path / "out.exr"
    p = subprocess.Popen(args(neepp_bin, out, 100000, "--checkpoint", 0.1))
    wait_for(Path(str(out) + ".checkpoint"), 60)
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=60)
    a = args(neepp_bin, out, 100000, "--resume")
    for i in range(0, len(change), 2):  # replace the option's value where it is given, else add it
        if change[i] in a:
            a[a.index(change[i]) + 1 if change[i] != "-D" else a.index("resx=160")] = change[i + 1]
        else:
            a += change[i:i + 2]
    r = subprocess.run(a, capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "of another render" in r.stderr and expect in r.stderr, r.stderr


def test_resume_without_a_checkpoint_is_refused(neepp_bin, tmp_path):
    r = subprocess.run(args(neepp_bin, tmp_path / "none.exr", 4, "--resume"), capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "no checkpoint" in r.stderr, r.stderr
