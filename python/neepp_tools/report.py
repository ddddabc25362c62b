"""Reports: side-by-side PNG of renders and false-colour relMSE error maps, markdown tables."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from . import metrics
from .exr import tonemap_srgb


def auto_exposure(ref: np.ndarray, percentile: float = 99.0) -> float:
    """Exposure that maps the given luminance percentile of ref to ~0.9 (for display only)."""
    lum = np.asarray(ref, dtype=np.float64).mean(axis=-1)
    p = float(np.percentile(lum, percentile))
    return 0.9 / p if p > 0 else 1.0


def save_png(path, img: np.ndarray, exposure: float = 1.0) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    Path(path).parent.mkdir(parents=True, exist_ok=True)
    plt.imsave(str(path), tonemap_srgb(img, exposure))


def comparison_figure(path, images: dict, ref: np.ndarray | None = None, title: str = "",
                      exposure: float | None = None, err_range: tuple = (1e-4, 1e1),
                      credit: str = "") -> dict:
    """Write a PNG: top row the images (and the reference), bottom row log-scale false-colour relMSE
    maps of each image against ref (same colour scale for all). Returns {name: relMSE}.

    images: {label: (H, W, 3) array}; ref: the reference or None (then no error row);
    credit: attribution line printed under the figure (neepp_tools.credit(scene) for CC-BY scenes).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    names = list(images)
    ncols = len(names) + (1 if ref is not None else 0)
    nrows = 2 if ref is not None else 1
    h, w = next(iter(images.values())).shape[:2]
    cw = 4.0
    fig, axes = plt.subplots(nrows, ncols, figsize=(cw * ncols, cw * h / w * nrows + 1.0 * nrows + 0.5),
                             squeeze=False)
    if exposure is None:
        exposure = auto_exposure(ref if ref is not None else images[names[0]])
    scores = {}
    cols = names + (["reference"] if ref is not None else [])
    for j, name in enumerate(cols):
        img = ref if name == "reference" else images[name]
        ax = axes[0][j]
        ax.imshow(tonemap_srgb(img, exposure))
        label = name
        if ref is not None and name != "reference":
            scores[name] = metrics.relmse(img, ref)
            label += f"\nrelMSE {scores[name]:.4g}, mean {metrics.image_mean(img):.4g}"
        elif name == "reference":
            label += f"\nmean {metrics.image_mean(img):.4g}"
        ax.set_title(label, fontsize=9)
        ax.axis("off")
    if ref is not None:
        norm = LogNorm(vmin=err_range[0], vmax=err_range[1])
        im = None
        for j, name in enumerate(cols):
            ax = axes[1][j]
            ax.axis("off")
            if name == "reference":
                continue
            emap = np.maximum(metrics.relmse_map(images[name], ref), err_range[0])
            im = ax.imshow(emap, cmap="inferno", norm=norm)
            ax.set_title(f"{name}: relMSE per pixel", fontsize=9)
        if im is not None:
            fig.colorbar(im, ax=axes[1][ncols - 1], fraction=0.9, label="relMSE (log)")
    if title:
        fig.suptitle(title, fontsize=11)
    fig_h = fig.get_size_inches()[1]
    top = 1 - (0.45 / fig_h if title else 0)
    bottom = 0.3 / fig_h if credit else 0
    fig.tight_layout(rect=(0, bottom, 1, top))
    if credit:
        fig.text(0.5, 0.05 / fig_h, credit, ha="center", va="bottom", fontsize=7)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(str(path), dpi=100)
    plt.close(fig)
    return scores


def error_map_rgba(img: np.ndarray, ref: np.ndarray, err_range: tuple = (1e-4, 1e1)) -> np.ndarray:
    """Per-pixel relMSE in false colour (inferno, log scale over err_range), RGBA in [0, 1]."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    emap = np.maximum(metrics.relmse_map(img, ref), err_range[0])
    return plt.get_cmap("inferno")(LogNorm(vmin=err_range[0], vmax=err_range[1])(emap))


def error_map_png(path, img: np.ndarray, ref: np.ndarray, err_range: tuple = (1e-4, 1e1)) -> None:
    """A single false-colour (log) relMSE map as a PNG of the image's size."""
    import matplotlib.pyplot as plt

    Path(path).parent.mkdir(parents=True, exist_ok=True)
    plt.imsave(str(path), error_map_rgba(img, ref, err_range))


def _fmt(v) -> str:
    if v is None:
        return "–"
    if isinstance(v, float):
        if v != v:
            return "nan"
        if v == 0:
            return "0"
        a = abs(v)
        if a >= 1e5 or a < 1e-3:
            return f"{v:.3e}"
        if a >= 100:
            return f"{v:.0f}"
        return f"{v:.4g}"
    return str(v)


def markdown_table(rows: list[dict], columns: list[str] | None = None,
                   headers: dict | None = None) -> str:
    """rows of dicts -> GitHub markdown table (columns default to the first row's keys)."""
    if not rows:
        return ""
    columns = columns or list(rows[0])
    headers = headers or {}
    out = ["| " + " | ".join(headers.get(c, c) for c in columns) + " |",
           "|" + "|".join("---" for _ in columns) + "|"]
    for r in rows:
        out.append("| " + " | ".join(_fmt(r.get(c)) for c in columns) + " |")
    return "\n".join(out)
