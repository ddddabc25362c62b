"""neepp_tools.metrics on small hand-computed arrays."""
import math

import numpy as np
import pytest

from neepp_tools import metrics


def test_relmse_hand_computed():
    ref = np.array([[[1.0, 0.0, 0.1]]])  # one pixel
    img = np.array([[[2.0, 0.1, 0.1]]])
    # (1)^2/(1+0.01), (0.1)^2/(0+0.01), 0
    expected = (1 / 1.01 + 0.01 / 0.01 + 0.0) / 3
    assert metrics.relmse(img, ref) == pytest.approx(expected, rel=1e-12)
    assert metrics.relmse_map(img, ref).shape == (1, 1)
    assert metrics.relmse_map(img, ref)[0, 0] == pytest.approx(expected, rel=1e-12)


def test_relmse_two_pixels_and_identity():
    ref = np.ones((1, 2, 3))
    img = np.ones((1, 2, 3))
    img[0, 1, :] = 0.5
    # three channels of the second pixel: 0.25/1.01, the first pixel 0
    assert metrics.relmse(img, ref) == pytest.approx(0.25 / 1.01 / 2, rel=1e-12)
    assert metrics.relmse(ref, ref) == 0.0


def test_rmse_mare_mean():
    ref = np.array([[[1.0, 2.0, 3.0]], [[0.0, 0.0, 0.0]]])  # (2, 1, 3)
    img = np.array([[[1.0, 2.0, 5.0]], [[0.0, 0.0, 0.01]]])
    assert metrics.rmse(img, ref) == pytest.approx(math.sqrt((4 + 1e-4) / 6), rel=1e-12)
    assert metrics.mean_abs_rel_error(img, ref) == pytest.approx((2 / 3.01 + 0.01 / 0.01) / 6, rel=1e-12)
    assert metrics.image_mean(img) == pytest.approx(8.01 / 6, rel=1e-12)


def test_shape_mismatch_raises():
    with pytest.raises(ValueError):
        metrics.relmse(np.zeros((2, 2, 3)), np.zeros((2, 3, 3)))


def test_mean_stderr_matches_iid_noise():
    rng = np.random.default_rng(1)
    ref = np.full((256, 256, 3), 2.0)
    sigma = 0.5
    img = ref + rng.normal(0, sigma, size=(256, 256, 1)).repeat(3, axis=-1)
    se = metrics.mean_stderr(img, ref, block=8)
    expected = sigma / math.sqrt(256 * 256)
    assert se == pytest.approx(expected, rel=0.15)


def test_relmse_of_unbiased_noise_is_variance_over_r2():
    rng = np.random.default_rng(2)
    ref = np.full((200, 200, 3), 1.0)
    img = ref + rng.normal(0, 0.1, size=ref.shape)
    assert metrics.relmse(img, ref) == pytest.approx(0.01 / 1.01, rel=0.02)


def test_relmse_stderr_matches_iid_noise():
    rng = np.random.default_rng(3)
    ref = np.full((256, 256, 3), 1.0)
    img = ref + rng.normal(0, 0.1, size=ref.shape)
    # per-pixel relMSE is (0.1^2/1.01) * chi2_3 / 3, whose std is mean * sqrt(2/3)
    m = 0.01 / 1.01
    expected = m * np.sqrt(2 / 3) / 256
    assert metrics.relmse_stderr(img, ref) == pytest.approx(expected, rel=0.15)


def test_relative_variance_matches_known_noise():
    # Two renders = truth + independent noise of standard deviation sigma * truth: relVar -> sigma^2
    # (normalized by ref^2 + eps, with ref = truth large enough that eps does not matter).
    rng = np.random.default_rng(5)
    ref = np.full((200, 200, 3), 4.0)
    sigma = 0.1
    a = ref * (1 + sigma * rng.standard_normal(ref.shape))
    b = ref * (1 + sigma * rng.standard_normal(ref.shape))
    assert metrics.relative_variance(a, b, ref) == pytest.approx(sigma**2 * 16 / (16 + metrics.EPS), rel=0.02)
    # A common offset (bias, which relmse against the reference would count) is invisible to it.
    assert metrics.relative_variance(a + 1, b + 1, ref) == pytest.approx(metrics.relative_variance(a, b, ref))
    assert metrics.relative_variance(a, a, ref) == 0


def test_paired_ratios_summary_and_sign_test():
    s = metrics.paired_ratios([2.0, 0.5, 1.5, 1.2, 1.1])
    assert s["n"] == 5 and s["above_1"] == 4
    assert s["median"] == pytest.approx(1.2)
    assert s["geomean"] == pytest.approx((2.0 * 0.5 * 1.5 * 1.2 * 1.1) ** (1 / 5))
    assert s["sign_test_p"] == pytest.approx(6 / 32)  # P(X >= 4), X ~ Binomial(5, 1/2)
    assert metrics.paired_ratios([1.1] * 5)["sign_test_p"] == pytest.approx(1 / 32)
    assert metrics.paired_ratios([0.9, 0.8])["sign_test_p"] == pytest.approx(1.0)
    # A 2x and a 0.5x cancel in the geometric mean; unusable entries are left out.
    assert metrics.paired_ratios([2.0, 0.5, None, float("nan")])["geomean"] == pytest.approx(1.0)
    assert metrics.paired_ratios([])["n"] == 0
