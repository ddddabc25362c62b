"""Read and write OpenEXR images as float32 numpy arrays of shape (H, W, 3).

Uses Mitsuba 3's ``mi.Bitmap`` (no variant needs to be set for it, and it never starts the
LLVM backend), falling back to the ``OpenEXR`` pip package when Mitsuba is not installed.
"""
from __future__ import annotations

import threading
from pathlib import Path

import numpy as np

_import_lock = threading.Lock()


def _mitsuba():
    # One import at a time: a second thread importing mitsuba while the first is still in it sees the module
    # half made (no Bitmap yet), as bench scripts rendering with --jobs 2 did.
    with _import_lock:
        try:
            import mitsuba as mi
        except ImportError:
            return None
        return mi


def read_exr(path) -> np.ndarray:
    """Return the RGB channels of an EXR file as float32 (H, W, 3). Alpha and extra layers are dropped."""
    path = str(path)
    if not Path(path).exists():
        raise FileNotFoundError(path)
    mi = _mitsuba()
    if mi is not None:
        bmp = mi.Bitmap(path)
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
        return np.array(bmp, dtype=np.float32, copy=True).reshape(bmp.height(), bmp.width(), 3)
    import OpenEXR  # pip install openexr (>= 3.3)

    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            img = np.asarray(ch["RGB"].pixels)
        elif "RGBA" in ch:
            img = np.asarray(ch["RGBA"].pixels)[..., :3]
        else:
            img = np.stack([np.asarray(ch[c].pixels) for c in ("R", "G", "B")], axis=-1)
    return np.ascontiguousarray(img, dtype=np.float32)


def write_exr(path, img: np.ndarray) -> None:
    """Write a float (H, W, 3) array as a float32 RGB EXR."""
    img = np.ascontiguousarray(np.asarray(img, dtype=np.float32))
    if img.ndim != 3 or img.shape[2] != 3:
        raise ValueError(f"expected (H, W, 3), got {img.shape}")
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    mi = _mitsuba()
    if mi is not None:
        mi.Bitmap(img, mi.Bitmap.PixelFormat.RGB).write(str(path))
        return
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {"RGB": img}) as f:
        f.write(str(path))


def tonemap_srgb(img: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """Clamp and sRGB-encode a linear image for display (float in [0, 1])."""
    x = np.clip(np.asarray(img, dtype=np.float64) * exposure, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
