"""The project's participating-media scenes built for NEE++ (issue 40): scenes/smoke-plume (a heterogeneous
plume from a generated grid, lamps partly behind walls) and scenes/sunbeam (a dusty room, a sun through a
window), beside scenes/door-ajar-fog.

smoke-plume's grid is generated, never committed: its generator (scenes/smoke-plume/make_plume.py) must give
the same bytes on every run, neepp_tools.scene_assets must make the file when it is missing, and a render
without it must stop with the loader's error naming the file. Each scene must load and render a few samples
with volpath, plain NEE and NEE++'s adaptive rejection, with no NaN, negative or black image, and NEE++'s
rejection must engage (the scenes exist to make it pay: more than half of the first pass's shadow rays
blocked) and trace under 0.7 times the shadow rays of NEE (about 0.5 at 16 spp, 64 x 36). Mitsuba 3 must
load and render them too. (Their images against Mitsuba's, with every light sampler:
tests/python/test_project_scenes.py.)
"""
from __future__ import annotations

import shutil
import struct
import subprocess
import sys

import numpy as np
import pytest

from neepp_tools import REPO_ROOT, exr, runner
from neepp_tools.scene_assets import GENERATED, ensure_scene_assets

SCENES = ["smoke-plume", "sunbeam"]
PLUME = REPO_ROOT / "scenes" / "smoke-plume"
OUT = REPO_ROOT / ".cache" / "test_media_scenes"
SMALL = {"resx": 64, "resy": 36}


@pytest.fixture(scope="module", autouse=True)
def assets():
    """The generated files of the scenes, made once if missing."""
    return {s: ensure_scene_assets(s) for s in SCENES}


def _generate(out) -> bytes:
    subprocess.run([sys.executable, str(PLUME / "make_plume.py"), "-o", str(out)], check=True, capture_output=True,
                   timeout=300)
    return out.read_bytes()


def test_plume_generator_is_deterministic_and_writes_a_mitsuba_grid(tmp_path):
    a, b = _generate(tmp_path / "a.vol"), _generate(tmp_path / "b.vol")
    assert a == b, "make_plume.py wrote different bytes on two runs"
    assert a[:4] == b"VOL\x03"
    kind, nx, ny, nz, channels = struct.unpack_from("<5i", a, 4)
    bbox = struct.unpack_from("<6f", a, 24)
    assert (kind, channels, bbox) == (1, 1, (0.0, 0.0, 0.0, 1.0, 1.0, 1.0))
    assert 48 <= min(nx, ny, nz) and max(nx, ny, nz) <= 64
    values = np.frombuffer(a, "<f4", offset=48)
    assert values.size == nx * ny * nz, "the data is not exactly one float per grid point"
    grid = values.reshape(nz, ny, nx)
    assert np.isfinite(grid).all() and grid.min() >= 0 and grid.max() == pytest.approx(1.0)
    # A plume: dense low in the middle, zero on the side faces (so the box never shows), wider higher up.
    assert grid[:, : ny // 4, nx // 2 - 4: nx // 2 + 4].max() > 0.5
    assert max(grid[:, :, 0].max(), grid[:, :, -1].max(), grid[0].max(), grid[-1].max()) == 0
    width = [(grid[:, y] > 0.05).sum() for y in (ny // 5, 3 * ny // 4)]
    assert width[1] > 2 * width[0], f"the plume does not widen as it rises ({width})"
    # The scene's copy is the generator's (the fixture made it if it was missing).
    assert (PLUME / "plume.vol").read_bytes() == a


def test_scene_assets_make_a_missing_grid(tmp_path):
    folder = tmp_path / "smoke-plume"
    folder.mkdir()
    shutil.copy(PLUME / "make_plume.py", folder)
    files = ensure_scene_assets("smoke-plume", scenes_dir=tmp_path)
    assert files == [folder / "plume.vol"] and files[0].read_bytes() == (PLUME / "plume.vol").read_bytes()
    assert ensure_scene_assets("sunbeam", scenes_dir=tmp_path) == []  # nothing generated there
    assert set(GENERATED) == {"smoke-plume"}


def test_render_without_the_grid_names_the_missing_file(tmp_path, neepp_bin):
    """A checkout where nobody ran the generator: the loader's error, at the grid's line, naming the file."""
    folder = tmp_path / "smoke-plume"
    folder.mkdir()
    shutil.copy(PLUME / "scene.xml", folder)
    r = subprocess.run([str(neepp_bin), "render", str(folder / "scene.xml"), "-o", str(tmp_path / "x.exr"),
                        "--spp", "1", "-D", "resx=8", "-D", "resy=8", "--quiet"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode != 0
    msg = r.stdout + r.stderr
    assert "plume.vol" in msg and "cannot open the volume grid file" in msg and "gridvolume" in msg, msg
    assert not (tmp_path / "x.exr").exists()


def _render(scene: str, policy: str, neepp_bin, spp: int = 16):
    return runner.run_neepp(REPO_ROOT / "scenes" / scene / "scene.xml", OUT / f"{scene}_{policy}.exr", spp=spp,
                            seed=5, defines=SMALL, integrator_args={"shadow_rays": policy}, binary=neepp_bin,
                            timeout=600)


@pytest.mark.parametrize("scene", SCENES)
def test_scene_renders_with_nee_and_neepp(scene, neepp_bin):
    nee, neepp = _render(scene, "nee", neepp_bin), _render(scene, "neepp-adaptive", neepp_bin)
    for r in (nee, neepp):
        img = r.image[..., :3]
        assert img.shape == (SMALL["resy"], SMALL["resx"], 3)
        assert np.isfinite(img).all(), f"{scene}: NaN or infinite pixels"
        assert img.min() >= 0, f"{scene}: negative pixels"
        assert r.stats["integrator"]["name"] == "volpath"
        assert r.stats["shadow_rays"] > 0
    assert 0.01 < float(nee.image[..., :3].mean()) < 5, f"{scene}: image mean {nee.image.mean()}"
    # The two estimate the same image: their means within a generous bound at these few samples.
    m0, m1 = float(nee.image[..., :3].mean()), float(neepp.image[..., :3].mean())
    assert abs(m1 - m0) < 0.25 * m0, f"{scene}: nee mean {m0}, neepp-adaptive mean {m1}"
    sr = neepp.stats["integrator_statistics"]["shadow_rays"]
    assert sr["rejection"]["state"] == "on", f"{scene}: NEE++'s rejection stayed off: {sr['rejection']}"
    assert neepp.stats["shadow_rays"] < 0.7 * nee.stats["shadow_rays"], \
        f"{scene}: NEE++ traced {neepp.stats['shadow_rays']} shadow rays, NEE {nee.stats['shadow_rays']}"


@pytest.mark.parametrize("scene", SCENES)
def test_scene_renders_in_mitsuba(scene, mitsuba_variant):
    r = runner.run_mitsuba(REPO_ROOT / "scenes" / scene / "scene.xml", OUT / f"mitsuba_{scene}.exr",
                           variant=mitsuba_variant, resx=32, resy=18, spp=4, max_depth=6, integrator="volpath",
                           timeout=600)
    img = r.image[..., :3]
    assert np.isfinite(img).all() and img.min() >= 0 and img.mean() > 0.01
