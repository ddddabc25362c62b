"""The project's own scenes (scenes/*/scene.xml: the demo and the many-light scenes) render the same
image in neepp as in Mitsuba 3 with every light sampler (and with NEE++'s rejection on top of the
visibility-aware one): the unbiasedness of each sampler on the many-light scenes, against an
independent renderer.

Each scene is rendered at a quarter of its default resolution with both renderers (Mitsuba cached under
.cache/mitsuba) and the image means are compared: the difference must stay within 4 standard errors
(estimated from the noise of neepp − Mitsuba over 8×8 tiles) plus 0.5 % (a bias that small is below
what these spp can resolve). A scene whose environment map lives in ../shared/scenes is skipped when
that is absent. The materials scene (every BSDF) gets its bitmap and environment map from this test,
made procedurally, and so checks every material against Mitsuba as well. The media scenes (door-ajar-fog,
smoke-plume, sunbeam) are rendered by both with volpath, their own integrator; smoke-plume's grid is
generated first when missing (neepp_tools.scene_assets).
"""
from __future__ import annotations

import functools
import re
from pathlib import Path

import numpy as np
import pytest

from neepp_tools import REPO_ROOT, exr, metrics, runner, scene_assets

SCENES = sorted(p.parent.name for p in (REPO_ROOT / "scenes").glob("*/scene.xml"))
SPP = 256
# The media scenes (volpath, several times a surface scene's cost per sample) at half the samples: the
# bound below widens with the noise, and 9 samplers x 3 scenes at 256 spp were a third of CI's pytest.
SPP_MEDIA = 128
MAX_DEPTH = 8
OUT = REPO_ROOT / ".cache" / "test_project_scenes"
_memo: dict = {}


def _size(xml: Path) -> tuple[int, int]:
    text = xml.read_text()
    w = int(re.search(r'<default name="resx" value="(\d+)"', text).group(1))
    h = int(re.search(r'<default name="resy" value="(\d+)"', text).group(1))
    return max(16, w // 4), max(16, h // 4)


def _integrator(xml: Path) -> str:
    """The scene's own integrator (its `integrator` parameter's default): Mitsuba renders the media scenes
    with volpath, as neepp does, not with its path (which renders them as if in vacuum)."""
    m = re.search(r'<default name="integrator" value="(\w+)"', xml.read_text())
    return m.group(1) if m else "path"


def _needs_missing_file(xml: Path, defines: dict) -> str | None:
    for m in re.finditer(r'<default name="(\w+)" value="([^"]+\.(?:exr|hdr|png|jpg))"', xml.read_text()):
        if m.group(1) not in defines and not (xml.parent / m.group(2)).exists():
            return m.group(2)
    return None


@functools.cache
def _defines(scene: str) -> dict:
    """Scene parameters this test supplies: the materials scene's images, made here once (deterministic)."""
    if scene != "materials":
        return {}
    from PIL import Image
    OUT.mkdir(parents=True, exist_ok=True)
    y, x = np.mgrid[0:64, 0:64] / 64.0
    # Colour stripes over a gradient with a few hard edges: sRGB colour, mask opacity and bump heights.
    rgb = np.stack([0.5 + 0.5 * np.sin(12 * x), y, (x + y) % 0.5 * 2], axis=-1)
    rgb[(x > 0.25) & (x < 0.35)] = 0.05
    texture, envmap = OUT / "materials_texture.png", OUT / "materials_envmap.exr"
    Image.fromarray((rgb * 255).round().astype(np.uint8)).save(texture)
    # A sky: blue above, dark below, and a small bright sun.
    v = np.repeat(np.arange(32)[:, None] / 32.0, 64, axis=1)
    sky = np.stack([0.3 + 0.2 * (1 - v), 0.4 + 0.3 * (1 - v), 0.9 * (1 - v) + 0.1], axis=-1) * (v < 0.55)[..., None]
    sky[4:7, 40:44] = (40.0, 36.0, 30.0)
    exr.write_exr(envmap, sky.astype(np.float32))
    return {"texture": str(texture), "envmap": str(envmap)}


def _spp(xml: Path) -> int:
    return SPP_MEDIA if _integrator(xml) == "volpath" else SPP


def mitsuba_image(xml: Path, variant: str, defines: dict):
    key = (xml, variant)
    if key not in _memo:
        w, h = _size(xml)
        _memo[key] = runner.run_mitsuba(xml, variant=variant, resx=w, resy=h, spp=_spp(xml), max_depth=MAX_DEPTH,
                                        seed=7, integrator=_integrator(xml), defines=defines, timeout=900,
                                        cache=True).image
    return _memo[key]


SAMPLERS = ["power", "uniform", "spatial", "spatial-oriented", "bvh", "visibility", "visibility-power",
            "visibility-bvh", "visibility+neepp-adaptive"]


@pytest.mark.parametrize("light_sampler", SAMPLERS)
@pytest.mark.parametrize("scene", SCENES)
def test_scene_matches_mitsuba(scene, light_sampler, neepp_bin, mitsuba_variant):
    xml = REPO_ROOT / "scenes" / scene / "scene.xml"
    scene_assets.ensure_scene_assets(scene)  # smoke-plume's grid, generated when missing
    defines = _defines(scene)
    missing = _needs_missing_file(xml, defines)
    if missing:
        pytest.skip(f"{scene} needs {missing} (from ../shared/scenes), which is absent")
    w, h = _size(xml)
    ref = mitsuba_image(xml, mitsuba_variant, defines)
    sampler, _, policy = light_sampler.partition("+")
    args = {"light_sampler": sampler} | ({"shadow_rays": policy} if policy else {})
    spp = _spp(xml)
    r = runner.run_neepp(xml, OUT / f"{scene}_{light_sampler}.exr", spp=spp, resx=w, resy=h, max_depth=MAX_DEPTH,
                         seed=11, integrator_args=args, defines=defines, binary=neepp_bin, timeout=600)
    m, mr = metrics.image_mean(r.image), metrics.image_mean(ref)
    se = metrics.mean_stderr(r.image, ref)
    msg = (f"{scene} ({light_sampler}, {w}x{h}, {spp} spp): neepp mean {m:.5g}, Mitsuba {mr:.5g}, "
           f"difference {(m - mr) / mr:+.3%}, standard error {se / mr:.3%}")
    print(msg)
    assert mr > 1e-4, f"{scene}: the Mitsuba render is black"
    assert abs(m - mr) < 4 * se + 0.005 * mr, msg
