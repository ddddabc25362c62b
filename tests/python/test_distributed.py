"""Distributed rendering on Ray (neepp.distributed): ranges of sample indices on workers of a local Ray
instance, summed by the driver to the same bits as the same ranges rendered in one process; NEE++'s maps
merged between rounds; a worker killed mid-range; a worker that cannot load the scene; loopback only."""
from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest

import neepp
import neepp.distributed as nd
from neepp import metrics

ray = pytest.importorskip("ray", reason="Ray is installed by scripts/setup_python.sh")

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEMO = os.path.join(REPO, "scenes", "door-ajar", "scene.xml")
SMALL = {"resx": 48, "resy": 32}


@pytest.fixture(scope="module", autouse=True)
def ray_instance():
    if ray.is_initialized():
        ray.shutdown()
    yield
    ray.shutdown()


@pytest.mark.parametrize("integrator,options", [("path", {}), ("path", {"shadow_rays": "neepp"}),
                                                ("bdpt", {}), ("bdpt", {"light_paths": "neepp", "candidates": 4})])
def test_two_workers_equal_one_process_rendering_the_same_ranges(integrator, options):
    a, sa = nd.render(DEMO, spp=12, workers=2, integrator=integrator, options=options, seed=3, **SMALL)
    b, sb = nd.render(DEMO, spp=12, workers=2, integrator=integrator, options=options, seed=3, local=True, **SMALL)
    assert np.array_equal(a, b)
    assert sa["distributed"]["ranges"] == sb["distributed"]["ranges"]
    assert sa["spp"] == 12 and sa["rays"] == sb["rays"] and sa["shadow_rays"] == sb["shadow_rays"]
    assert a.shape == (32, 48, 3) and a.mean() > 0
    ranges = sa["distributed"]["ranges"]
    assert ranges[0] == [0, 1] and ranges[-1][1] == 12
    assert all(r[1] == s[0] for r, s in zip(ranges, ranges[1:]))  # every index once
    if options.get("shadow_rays") == "neepp" or options.get("light_paths") == "neepp":
        assert sa["distributed"]["rounds"] > 2  # learning: rounds that grow, maps merged between them
    else:
        assert sa["distributed"]["rounds"] == 2  # nothing learned: everything after sample 0 at once


def test_plain_path_tracing_is_the_single_render():
    # Without learning, the ranges' samples are exactly a one-process render's samples.
    img, stats = nd.render(DEMO, spp=8, workers=2, seed=5, **SMALL)
    ref, ref_stats = neepp.render(neepp.load(DEMO, **SMALL), spp=8, seed=5)
    assert np.array_equal(img, ref) and stats["rays"] == ref_stats["rays"]


def test_neepp_distributed_agrees_with_plain_nee():
    # Maps merged across workers keep NEE++ unbiased: the mean agrees with plain NEE's (another seed).
    img, stats = nd.render(DEMO, spp=64, workers=2, options={"shadow_rays": "neepp"}, seed=11, **SMALL)
    ref, _ = neepp.render(neepp.load(DEMO, **SMALL), spp=256, seed=12)
    assert stats["shadow_rays_skipped"] > 0  # rejection was on
    diff = metrics.image_mean(img) - metrics.image_mean(ref)
    se = metrics.mean_stderr(img, ref, block=4)
    assert abs(diff) < 4 * se, (diff, se)


def test_a_killed_worker_has_its_range_rendered_again(tmp_path):
    ray.shutdown()
    os.environ["NEEPP_DISTRIBUTED_KILL_ONCE"] = str(tmp_path)  # the workers of the next Ray instance see it
    try:
        img, stats = nd.render(DEMO, spp=24, workers=2, seed=2, **SMALL)
    finally:
        del os.environ["NEEPP_DISTRIBUTED_KILL_ONCE"]
        ray.shutdown()
    killed = tmp_path / "killed"
    assert killed.exists(), "no worker was killed"
    pid = int(killed.read_text())
    assert not os.path.exists(f"/proc/{pid}") or "ray" not in open(f"/proc/{pid}/cmdline").read()
    ref, _ = nd.render(DEMO, spp=24, workers=2, seed=2, local=True, **SMALL)
    assert np.array_equal(img, ref)  # nothing lost, nothing counted twice
    assert stats["spp"] == 24


def test_a_scene_a_worker_cannot_load_is_one_clear_error(tmp_path):
    runner = nd._Ray(None, 1, 1)
    missing = str(tmp_path / "not-on-this-worker.xml")
    with pytest.raises(neepp.SceneError) as e:
        runner.wait([runner.submit(missing, {}, "path", {}, 0, 1, 0, 1, "independent", b"")], lambda r: None)
    assert e.value.file == missing and "cannot open" in str(e.value)


def test_bad_arguments():
    with pytest.raises(neepp.SceneError):
        nd.render(os.path.join(REPO, "no-such-scene.xml"), spp=1)
    with pytest.raises(ValueError, match="pssmlt"):
        nd.render(DEMO, spp=1, integrator="pssmlt", **SMALL)
    with pytest.raises(ValueError):
        nd.render(DEMO, spp=1, time=1, **SMALL)
    with pytest.raises(ValueError):
        nd.render(DEMO, spp=1, workers=0, **SMALL)


def test_time_limit_and_progress():
    seen = []
    img, stats = nd.render(DEMO, time=3, workers=2, progress=seen.append, **SMALL)
    assert stats["stopped_by"] == "time" and stats["spp"] > 1 and 2.5 < stats["render_time_s"] < 8
    assert seen[-1] == 1.0 and all(a <= b for a, b in zip(seen, seen[1:]))


def test_a_local_instance_listens_on_loopback_only():
    nd.render(DEMO, spp=2, workers=2, **SMALL)  # starts (or reuses) the local instance
    out = subprocess.run(["ss", "-ltnpH"], capture_output=True, text=True).stdout
    ray_sockets = [line.split() for line in out.splitlines()
                   if any(k in line for k in ("raylet", "gcs_server", "ray::", f"pid={os.getpid()},"))]
    assert ray_sockets, out
    for fields in ray_sockets:
        local = fields[3]
        assert local.startswith("127.0.0.1:") or local.startswith("[::ffff:127.0.0.1]:"), fields


def test_the_cli_renders_on_ray(tmp_path):
    cli = os.path.join(os.path.dirname(neepp.__file__), "bin", "neepp")  # the package's CLI: the same build
    common = [DEMO, "--spp", "8", "--seed", "4", "-D", "resx=48", "-D", "resy=32", "-q"]
    r = subprocess.run([cli, "render", *common, "-o", str(tmp_path / "ray" / "a.exr"), "--ray", "--workers", "2",
                        "--stats", str(tmp_path / "ray" / "a.json")], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    r = subprocess.run([cli, "render", *common, "-o", str(tmp_path / "b.exr")], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    assert np.array_equal(neepp.read_exr(tmp_path / "ray" / "a.exr"), neepp.read_exr(tmp_path / "b.exr"))
    assert (tmp_path / "ray" / "a.png").exists()
    import json
    stats = json.loads((tmp_path / "ray" / "a.json").read_text())
    assert stats["spp"] == 8 and stats["distributed"]["workers"] == 2
    r = subprocess.run([cli, "render", *common, "-o", str(tmp_path / "c.exr"), "--ray", "--display-server",
                        "127.0.0.1:14158"], capture_output=True, text=True, timeout=300)
    assert r.returncode != 0 and "--display-server is not available with --ray" in r.stderr
