"""The pure parts of bench/mitsuba_suite.py: Mitsuba 3's per-pixel z-test (neepp_tools.metrics) on synthetic
images, where a render with the reference's expectation passes and a biased one fails, and how the
script finds a scene's integrator, reference files, sample count and media."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from neepp_tools import metrics

REPO = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("mitsuba_suite", REPO / "bench" / "mitsuba_suite.py")
suite = importlib.util.module_from_spec(spec)
spec.loader.exec_module(suite)

SPP = 256


def synthetic(seed: int, bias: float = 0.0, spp: int = SPP):
    """A reference (a gradient), its per-sample variance, and a render: the mean of spp samples with that
    variance around reference * (1 + bias)."""
    rng = np.random.default_rng(seed)
    h, w = 48, 64
    ref = np.linspace(0.1, 2.0, h * w * 3).reshape(h, w, 3)
    var = 0.5 * ref
    img = ref * (1 + bias) + rng.standard_normal(ref.shape) * np.sqrt(var / spp)
    return img, ref, var


def test_sidak_alpha_keeps_the_family_level():
    a = metrics.sidak_alpha(0.01, 2304)
    assert (1 - a) ** 2304 == pytest.approx(0.99)
    assert metrics.sidak_alpha(0.01, 1) == pytest.approx(0.01)


def test_pvalues_of_known_z():
    ref, var = np.zeros((1, 1, 3)), np.ones((1, 1, 3))
    mean = np.array([[[0.0, 1.959964, 3.0]]]) / np.sqrt(100)  # z = 0, 1.96, 3 at spp = 100
    p = metrics.pixel_z_test_pvalues(mean, 100, ref, var)
    assert p.ravel() == pytest.approx([1.0, 0.05, 0.0026998], rel=1e-4)


def test_matching_render_passes():
    for seed in range(3):
        img, ref, var = synthetic(seed)
        assert metrics.z_test_pass_fraction(img, SPP, ref, var) >= suite.PASS_FRACTION
        assert metrics.mean_z_squared(img, SPP, ref, var) == pytest.approx(1.0, abs=0.1)
        assert suite.judge(img, SPP, ref, var)["passed"]


def test_biased_render_fails():
    # The per-pixel test needs many samples to see a small bias: 5 % at 16384 spp is 9 sqrt(ref) sigmas.
    img, ref, var = synthetic(0, bias=0.05, spp=16384)
    res = suite.judge(img, 16384, ref, var)
    assert not res["passed"] and res["pass_fraction"] < suite.PASS_FRACTION
    assert res["mean_ratio"] == pytest.approx(1.05, abs=0.005)


def test_noisier_render_shows_in_mean_z2_and_nan_fails():
    img, ref, var = synthetic(1)
    noisy = ref + (img - ref) * np.sqrt(1.4)  # 1.4x the per-sample variance, still unbiased
    assert metrics.mean_z_squared(noisy, SPP, ref, var) == pytest.approx(1.4, abs=0.1)
    img[3, 4, 1] = np.nan
    assert metrics.pixel_z_test_pvalues(img, SPP, ref, var)[3, 4, 1] != metrics.pixel_z_test_pvalues(
        img, SPP, ref, var)[3, 4, 1]
    assert metrics.z_test_pass_fraction(img, SPP, ref, var) < 1.0


def test_scene_naming_spp_and_media(tmp_path):
    folder = tmp_path / "tests" / "scenes" / "spheres"
    (folder / "include").mkdir(parents=True)
    (folder / "include" / "base.xml").write_text("<scene><medium type='homogeneous'/></scene>")
    plain = folder / "test_rough_plastic_path.xml"
    plain.write_text("<scene><shape type='sphere'/></scene>")
    foggy = folder / "test_fog_volpath.xml"
    foggy.write_text("<scene><include filename='include/base.xml'/></scene>")
    assert suite.scene_folder(tmp_path) == tmp_path / "tests" / "scenes"
    assert suite.suite_scenes(suite.scene_folder(tmp_path)) == [foggy, plain]
    assert suite.integrator_of(plain) == "path"
    ref, var = suite.reference_files(plain)
    assert ref == folder / "refs" / "test_rough_plastic_ref_rgb.exr"
    assert var == folder / "refs" / "test_rough_plastic_ref_rgb_var.exr"
    assert suite.harness_spp(48, 48) == 868 and suite.harness_spp(512, 64) == 61
    assert suite.harness_spp(48, 48, 0.25) == 217
    assert suite.uses_media(foggy) and not suite.uses_media(plain)
