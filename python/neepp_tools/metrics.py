"""Error metrics of shared/design/EVALUATION.md. Images are float arrays (H, W, 3), linear RGB.

- relMSE: mean over pixels and RGB channels of (I - R)^2 / (R^2 + 0.01)
- RMSE: sqrt(mean((I - R)^2))
- mean absolute relative error: mean(|I - R| / (|R| + 0.01))
"""
from __future__ import annotations

import math

import numpy as np

EPS = 0.01

__all__ = ["EPS", "downsample", "relmse_map", "relmse", "relative_variance", "rmse", "mean_abs_rel_error",
           "image_mean", "mean_stderr", "relmse_stderr", "block_z_scores", "block_agreement", "all_metrics",
           "paired_ratios", "RGB_TO_XYZ", "rgb_to_xyz", "sidak_alpha", "pixel_z_test_pvalues", "z_test_pass_fraction",
           "mean_z_squared"]


def _pair(img, ref):
    a = np.asarray(img, dtype=np.float64)
    r = np.asarray(ref, dtype=np.float64)
    if a.shape != r.shape:
        raise ValueError(f"image shape {a.shape} != reference shape {r.shape}")
    return a, r


def downsample(img, f: int) -> np.ndarray:
    """Box-downsample (H, W, 3) by an integer factor f (a render at 1/f the resolution with the box filter
    estimates this image of the full-resolution reference)."""
    img = np.asarray(img)
    h, w = img.shape[0] // f, img.shape[1] // f
    return img[: h * f, : w * f].reshape(h, f, w, f, 3).mean(axis=(1, 3))


def relmse_map(img, ref, eps: float = EPS) -> np.ndarray:
    """Per-pixel relMSE averaged over channels, shape (H, W)."""
    a, r = _pair(img, ref)
    m = (a - r) ** 2 / (r * r + eps)
    return m.mean(axis=-1) if m.ndim == 3 else m


def relmse(img, ref, eps: float = EPS) -> float:
    a, r = _pair(img, ref)
    return float(np.mean((a - r) ** 2 / (r * r + eps)))


def relative_variance(img_a, img_b, ref, eps: float = EPS) -> float:
    """Per-pixel variance of an unbiased renderer from two independent renders (different seeds) of the same
    scene and time or spp: E[(a - b)^2] = 2 Var, normalized like relmse by ref^2 + eps. Unlike relmse
    against a reference it holds no floor from the reference's own noise or from systematic differences
    between renderers (pixel filter, texture decoding), so ratios of it compare noise alone."""
    a, r = _pair(img_a, ref)
    b, _ = _pair(img_b, ref)
    return float(np.mean((a - b) ** 2 / (r * r + eps)) / 2)


def rmse(img, ref) -> float:
    a, r = _pair(img, ref)
    return float(np.sqrt(np.mean((a - r) ** 2)))


def mean_abs_rel_error(img, ref, eps: float = EPS) -> float:
    a, r = _pair(img, ref)
    return float(np.mean(np.abs(a - r) / (np.abs(r) + eps)))


def image_mean(img) -> float:
    """Mean over pixels and channels."""
    return float(np.mean(np.asarray(img, dtype=np.float64)))


def mean_stderr(img, ref, block: int = 8) -> float:
    """Standard error of image_mean(img) as an estimate of image_mean(ref), from the noise in img - ref.

    The difference image is averaged over block x block tiles (the reconstruction filter correlates
    neighbouring pixels, tiles make the tile means nearly independent); the standard error is
    std(tile means) / sqrt(number of tiles). It includes the reference's own noise, which is small
    when the reference has many more samples.
    """
    a, r = _pair(img, ref)
    d = (a - r).mean(axis=-1) if a.ndim == 3 else a - r
    h, w = d.shape
    hb, wb = h // block, w // block
    if hb * wb < 2:
        return float(np.std(d) / np.sqrt(d.size))
    tiles = d[: hb * block, : wb * block].reshape(hb, block, wb, block).mean(axis=(1, 3))
    return float(np.std(tiles, ddof=1) / np.sqrt(tiles.size))


def block_z_scores(a, b, block: int = 8) -> np.ndarray:
    """Per block of block x block pixels: z of the mean of the per-pixel difference a - b (mean over the
    channels), its variance from the block's own differences. Where both images estimate the same one, the
    difference is noise of mean zero in every pixel (the image's structure cancels), so this tests
    agreement locally."""
    x, y = _pair(a, b)
    d = x.mean(axis=2) - y.mean(axis=2)
    h, w = (d.shape[0] // block) * block, (d.shape[1] // block) * block
    blocks = d[:h, :w].reshape(h // block, block, w // block, block).transpose(0, 2, 1, 3).reshape(-1, block * block)
    se = blocks.std(axis=1, ddof=1) / math.sqrt(block * block)
    return np.where(se > 0, blocks.mean(axis=1) / np.maximum(se, 1e-30), 0.0)


def block_agreement(a, b, block: int = 8, level: float = 0.01) -> tuple[float, float, int]:
    """(fraction of blocks whose |z| is below the critical value, that value, the number of blocks): the
    block_z_scores with a Sidak correction, so that all blocks together fail with probability `level`
    when the images agree."""
    z = block_z_scores(a, b, block)
    alpha = 1 - (1 - level) ** (1 / len(z))
    z_crit = math.sqrt(2) * _erfinv(1 - alpha)
    return float(np.mean(np.abs(z) < z_crit)), z_crit, len(z)


def _erfinv(y: float) -> float:
    # Newton on erf, from a good start: precise enough for a critical value.
    x = math.sqrt(-math.log((1 - y) / 2)) if y > 0.5 else 0.0
    for _ in range(60):
        x -= (math.erf(x) - y) / (2 / math.sqrt(math.pi) * math.exp(-x * x))
    return x


def relmse_stderr(img, ref, block: int = 8, eps: float = EPS) -> float:
    """Standard error of relmse(img, ref) from its spread over block x block tiles (absolute, not relative).

    At low spp the per-render relMSE is dominated by rare bright samples (fireflies) and fluctuates
    from seed to seed by several percent; this estimates that fluctuation from one image.
    """
    e = relmse_map(img, ref, eps)
    h, w = e.shape
    hb, wb = h // block, w // block
    if hb * wb < 2:
        return float(np.std(e) / np.sqrt(e.size))
    tiles = e[: hb * block, : wb * block].reshape(hb, block, wb, block).mean(axis=(1, 3))
    return float(np.std(tiles, ddof=1) / np.sqrt(tiles.size))


def all_metrics(img, ref) -> dict:
    return {
        "relmse": relmse(img, ref),
        "rmse": rmse(img, ref),
        "mean_abs_rel_error": mean_abs_rel_error(img, ref),
        "mean": image_mean(img),
        "ref_mean": image_mean(ref),
        "mean_ratio": image_mean(img) / image_mean(ref) if image_mean(ref) != 0 else float("nan"),
        "mean_stderr": mean_stderr(img, ref),
        "relmse_stderr": relmse_stderr(img, ref),
    }


def paired_ratios(ratios) -> dict:
    """Summary of per-repetition speed ratios (a / b, each from two runs taken back to back).

    On a noisy machine one repetition can land on either side of 1 whatever the true ratio, so beside the
    median this gives the geometric mean (the mean of log ratios: a 2x and a 0.5x cancel) and an exact
    one-sided sign test: the probability of at least this many ratios above 1 if a and b were equally fast
    (each repetition then a coin toss). It assumes nothing about the noise's distribution; five
    repetitions all above 1 give p = 1/32.
    """
    rs = [float(r) for r in ratios if r is not None and r > 0 and math.isfinite(r)]
    n = len(rs)
    if n == 0:
        return {"n": 0, "median": None, "geomean": None, "above_1": 0, "sign_test_p": None}
    above = sum(r > 1 for r in rs)
    p = sum(math.comb(n, k) for k in range(above, n + 1)) / 2**n
    return {"n": n, "median": float(np.median(rs)), "geomean": math.exp(sum(map(math.log, rs)) / n),
            "above_1": above, "sign_test_p": p}


# Linear Rec. 709 RGB to CIE XYZ with the coefficients of Mitsuba 3's srgb_to_xyz: its render tests compare
# images in XYZ, and a variance image written as RGB goes back to XYZ through the same matrix.
RGB_TO_XYZ = np.array([[0.412453, 0.357580, 0.180423],
                       [0.212671, 0.715160, 0.072169],
                       [0.019334, 0.119193, 0.950227]])

_erfc = np.vectorize(math.erfc, otypes=[np.float64])


def rgb_to_xyz(img) -> np.ndarray:
    return np.asarray(img, dtype=np.float64)[..., :3] @ RGB_TO_XYZ.T


def sidak_alpha(level: float, tests: int) -> float:
    """Per-test significance that keeps the chance of any false rejection among `tests` independent
    tests at `level` (Šidák)."""
    return 1.0 - (1.0 - level) ** (1.0 / tests)


def _z(mean, spp: int, ref, ref_var, min_var: float):
    # The floor keeps pixels the reference saw (nearly) no variance in from failing on rounding alone.
    return np.abs(np.asarray(mean, np.float64) - ref) * np.sqrt(spp / np.maximum(ref_var, min_var))


def pixel_z_test_pvalues(mean, spp: int, ref, ref_var, min_var: float = 1e-4) -> np.ndarray:
    """Two-sided p-value, per pixel and channel, that `mean` (an average of spp independent samples) has
    the expectation `ref`, where ref_var is the per-sample variance: the statistic of Mitsuba 3's render
    tests (src/render/tests/test_renders.py), its variance floor included. A NaN pixel gets p = NaN,
    which fails any test."""
    return _erfc(_z(mean, spp, ref, ref_var, min_var) / math.sqrt(2.0))  # 2 (1 - Phi(z))


def z_test_pass_fraction(mean, spp: int, ref, ref_var, level: float = 0.01, min_var: float = 1e-4) -> float:
    """Fraction of pixel channels whose p-value exceeds the Šidák-corrected level over the pixel count.
    Mitsuba 3 accepts a render when it is at least 0.9975."""
    p = pixel_z_test_pvalues(mean, spp, ref, ref_var, min_var)
    pixels = p.shape[0] * p.shape[1]
    return float(np.count_nonzero(p > sidak_alpha(level, pixels)) / p.size)


def mean_z_squared(mean, spp: int, ref, ref_var, min_var: float = 1e-4) -> float:
    """Mean of z^2 over the pixel channels whose reference variance is above the floor. For an unbiased
    `mean` it estimates (its per-sample variance) / (the reference's): 1 when both estimators are equally
    noisy; bias adds to it."""
    z = _z(mean, spp, ref, ref_var, min_var)
    keep = np.asarray(ref_var) > min_var
    return float(np.mean(np.square(z[keep]))) if keep.any() else float("nan")
