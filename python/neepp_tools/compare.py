"""`neepp compare`: render one scene with several methods for the same wall time (or, with --spp, the same
sample count) and write what a person compares them with:

- DIR/index.html, one self-contained page (images inlined, no network): the renders side by side and in
  an A/B viewer (slider, zoom with the wheel, pan by dragging) over the images, their per-pixel
  relative-error maps and their FLIP maps; a table of the numbers; the convergence plot;
- DIR/results.json, every number the page shows (the page's table is built from a copy of it);
- DIR/figures/*.png: the images, error maps, FLIP maps, a side-by-side figure and the convergence plot,
  for papers; DIR/renders/: the EXRs, statistics and snapshots the numbers come from.

A method is an integrator with options: `path`, `path:nee=false`, `bdpt:light_paths=neepp:candidates=4`,
`pssmlt`, `path:shadow_rays=neepp` (integrator, then `:key=value` as `-I key=value`).

Errors need a reference (`--reference REF.exr`, the render's size or an integer multiple of it, then
box-downsampled: render with `--rfilter box` to compare against it). relMSE is EVALUATION.md's, against
the reference; the relative variance is from two seeds (`--seeds 2`, free of the reference's own error);
mean FLIP is NVIDIA's FLIP (HDR) against the reference (`flip-evaluator` from PyPI). The convergence plot
is relMSE against render time, log-log, from the snapshots each render writes (`neepp render
--snapshots`).
"""
from __future__ import annotations

import argparse
import base64
import html
import json
import sys
from pathlib import Path

if __name__ == "__main__":  # `neepp compare`: say what is missing before importing it
    from .requirements import COMPARE_ANY_OF, COMPARE_REQUIRED, require

    require("neepp compare", COMPARE_REQUIRED, COMPARE_ANY_OF)

import numpy as np

from . import credit, machine, metrics, runner
from .exr import read_exr, tonemap_srgb
from .report import auto_exposure, error_map_rgba

ERR_RANGE = (1e-4, 1e1)


def parse_method(spec: str) -> dict:
    """`integrator[:key=value...]` -> {"label", "integrator", "options"}."""
    parts = spec.split(":")
    integrator, options = parts[0], {}
    if not integrator:
        raise ValueError(f"method '{spec}': no integrator named")
    for p in parts[1:]:
        key, eq, value = p.partition("=")
        if not eq or not key:
            raise ValueError(f"method '{spec}': '{p}' is not key=value")
        options[key] = value
    return {"label": spec, "integrator": integrator, "options": options}


def slug(label: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in label)


def _png_bytes(rgb01: np.ndarray) -> bytes:
    from io import BytesIO

    from PIL import Image

    buf = BytesIO()
    Image.fromarray((np.clip(rgb01, 0, 1) * 255 + 0.5).astype(np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def _flip(img: np.ndarray, ref: np.ndarray):
    """(FLIP map as RGB in [0, 1], mean FLIP), or (None, None) without flip-evaluator."""
    try:
        import flip_evaluator as flip
    except ImportError:
        return None, None
    fmap, mean, _ = flip.evaluate(np.ascontiguousarray(ref, dtype=np.float32),
                                  np.ascontiguousarray(np.maximum(img, 0), dtype=np.float32), "HDR")
    return np.asarray(fmap, dtype=np.float64)[..., :3], float(mean)


def load_reference(path, shape) -> np.ndarray:
    ref = read_exr(path)
    h, w = shape[:2]
    if ref.shape[:2] == (h, w):
        return ref
    f = ref.shape[0] // h
    if f >= 1 and ref.shape[0] == f * h and ref.shape[1] == f * w:
        return metrics.downsample(ref, f)
    raise ValueError(f"the reference {path} is {ref.shape[1]}x{ref.shape[0]}, the renders {w}x{h}: it must be the "
                     "same size or an integer multiple of it")


def render_methods(args, methods: list[dict], out: Path) -> dict:
    """Renders every method and seed; returns {label: [RenderResult per seed]} and snapshot lists."""
    renders = {}
    for m in methods:
        runs = []
        for s in range(args.seeds):
            exr = out / "renders" / f"{slug(m['label'])}_seed{s}.exr"
            snaps = exr.with_suffix("")
            snaps = snaps.parent / (snaps.name + "_snapshots")
            extra = ["--snapshots", str(snaps)] + (["--rfilter", args.rfilter] if args.rfilter else [])
            if args.threads:
                extra += ["--threads", str(args.threads)]
            print(f"neepp compare: {m['label']} (seed {args.seed + s}) for "
                  f"{f'{args.spp} spp' if args.spp else f'{args.time} s'}", file=sys.stderr, flush=True)
            r = runner.run_neepp(args.scene, exr, spp=args.spp, time_s=None if args.spp else args.time,
                                 seed=args.seed + s, integrator=m["integrator"], integrator_args=m["options"],
                                 defines=dict(d.split("=", 1) for d in args.define), binary=args.neepp,
                                 timeout=None, extra_args=extra)
            index = json.loads((snaps / "snapshots.json").read_text()) if (snaps / "snapshots.json").exists() else []
            runs.append((r, snaps, index))
        renders[m["label"]] = runs
    return renders


def compute_results(args, methods, renders, ref) -> tuple[dict, dict]:
    """The numbers (results.json) and the images the page shows."""
    first = renders[methods[0]["label"]][0][0].image
    exposure = auto_exposure(ref if ref is not None else first)
    results = {"scene": str(args.scene), "mode": "equal spp" if args.spp else "equal time",
               "time_s": None if args.spp else args.time, "spp": args.spp, "seeds": args.seeds,
               "reference": str(args.reference) if args.reference else None,
               "width": int(first.shape[1]), "height": int(first.shape[0]), "exposure": exposure,
               "machine": machine.describe(), "credit": credit(Path(args.scene).resolve().parent.name),
               "methods": []}
    pictures = {}
    flip_missing = False
    for m in methods:
        runs = renders[m["label"]]
        r0 = runs[0][0]
        st = r0.stats
        row = {"label": m["label"], "integrator": m["integrator"], "options": m["options"],
               "spp": st.get("spp"), "render_time_s": st.get("render_time_s"), "rays": st.get("rays"),
               "shadow_rays": st.get("shadow_rays"), "occlusion_time_s": st.get("occlusion_time_s"),
               "image_mean": metrics.image_mean(r0.image), "relmse": None, "relmse_seeds": None,
               "rel_variance": None, "mean_flip": None, "convergence": []}
        pic = {"image": tonemap_srgb(r0.image, exposure)}
        if len(runs) >= 2:
            row["rel_variance"] = metrics.relative_variance(runs[0][0].image, runs[1][0].image,
                                                            ref if ref is not None else
                                                            0.5 * (runs[0][0].image + runs[1][0].image))
        if ref is not None:
            row["relmse"] = metrics.relmse(r0.image, ref)
            row["relmse_seeds"] = [metrics.relmse(r.image, ref) for r, _, _ in runs]
            pic["error"] = error_map_rgba(r0.image, ref, ERR_RANGE)[..., :3]
            fmap, fmean = _flip(r0.image, ref)
            if fmap is None:
                flip_missing = True
            else:
                pic["flip"], row["mean_flip"] = fmap, fmean
            _, snaps, index = runs[0]
            for s in index:
                img = read_exr(snaps / s["file"])
                row["convergence"].append({"render_time_s": s["render_time_s"], "spp": s["spp"],
                                           "relmse": metrics.relmse(img, ref)})
        results["methods"].append(row)
        pictures[m["label"]] = pic
    if ref is not None:
        pictures["reference"] = {"image": tonemap_srgb(ref, exposure)}
    if flip_missing:
        results["note"] = "mean FLIP not computed: install flip-evaluator (pip) for it"
    return results, pictures


def convergence_png(path: Path, results: dict) -> bool:
    """relMSE against render time, log-log, one line per method; False when there is nothing to plot."""
    rows = [r for r in results["methods"] if len(r["convergence"]) >= 1]
    if not rows:
        return False
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for r in rows:
        t = [c["render_time_s"] for c in r["convergence"]]
        e = [c["relmse"] for c in r["convergence"]]
        ax.loglog(t, e, marker="o", markersize=3, label=r["label"])
    ax.set_xlabel("render time (s)")
    ax.set_ylabel("relMSE")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(Path(results["scene"]).parent.name + ": convergence", fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(str(path), dpi=110)
    plt.close(fig)
    return True


def side_by_side_png(path: Path, pictures: dict, results: dict) -> None:
    """The images in a row, error maps below (when there is a reference), for a paper."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = list(pictures)
    rows = 2 if any("error" in p for p in pictures.values()) else 1
    h, w = pictures[labels[0]]["image"].shape[:2]
    fig, axes = plt.subplots(rows, len(labels), figsize=(3.2 * len(labels), 3.2 * h / w * rows + 0.8 * rows),
                             squeeze=False)
    by_label = {r["label"]: r for r in results["methods"]}
    for j, label in enumerate(labels):
        axes[0][j].imshow(pictures[label]["image"])
        r = by_label.get(label)
        title = label if r is None or r["relmse"] is None else f"{label}\nrelMSE {r['relmse']:.4g}, {r['spp']} spp"
        axes[0][j].set_title(title, fontsize=8)
        for i in range(rows):
            axes[i][j].axis("off")
        if rows == 2 and "error" in pictures[label]:
            axes[1][j].imshow(pictures[label]["error"])
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(str(path), dpi=110)
    plt.close(fig)


def write_report(out: Path, results: dict, pictures: dict) -> None:
    figures = out / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    inline = {}  # label -> layer -> data URI
    for label, layers in pictures.items():
        inline[label] = {}
        for layer, rgb in layers.items():
            data = _png_bytes(rgb)
            (figures / f"{slug(label)}_{layer}.png").write_bytes(data)
            inline[label][layer] = "data:image/png;base64," + base64.b64encode(data).decode()
    plot = None
    if convergence_png(figures / "convergence.png", results):
        plot = "data:image/png;base64," + base64.b64encode((figures / "convergence.png").read_bytes()).decode()
    side_by_side_png(figures / "side_by_side.png", pictures, results)
    (out / "results.json").write_text(json.dumps(results, indent=1) + "\n")
    page = (PAGE.replace("@TITLE@", html.escape(f"neepp compare: {Path(results['scene']).parent.name}"))
                .replace("@RESULTS@", json.dumps(results).replace("</", "<\\/"))
                .replace("@IMAGES@", json.dumps(inline))
                .replace("@PLOT@", json.dumps(plot)))
    (out / "index.html").write_text(page)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="neepp compare", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", type=Path, help="Scene file (Mitsuba 3 XML)")
    p.add_argument("--methods", required=True, help="Comma-separated methods, e.g. path,bdpt,pssmlt,path:shadow_rays=neepp")
    p.add_argument("--time", type=float, default=10.0, help="Seconds each method renders for (default 10)")
    p.add_argument("--spp", type=int, default=None, help="Equal sample count instead of equal time")
    p.add_argument("--reference", type=Path, default=None, help="Reference EXR (same size or an integer multiple)")
    p.add_argument("--seeds", type=int, default=1, help="Renders per method (2 gives the relative variance)")
    p.add_argument("--seed", type=int, default=0, help="First seed")
    p.add_argument("--threads", type=int, default=None)
    p.add_argument("--rfilter", default=None, choices=["box", "tent", "gaussian"],
                   help="Override the film's filter (box to compare with a box-downsampled reference)")
    p.add_argument("-D", dest="define", action="append", default=[], help="Scene parameter name=value")
    p.add_argument("-o", "--output-dir", type=Path, default=Path("neepp-compare"))
    p.add_argument("--neepp", type=Path, default=None, help="The neepp binary (default: the one that runs this)")
    args = p.parse_args(argv)
    try:
        methods = [parse_method(s) for s in args.methods.split(",") if s]
        if not methods:
            raise ValueError("--methods names no method")
        if len({m["label"] for m in methods}) != len(methods):
            raise ValueError("--methods names a method twice")
        if args.seeds < 1 or (args.spp is not None and args.spp < 1) or not args.time > 0:
            raise ValueError("--seeds and --spp must be at least 1, --time positive")
        if not args.scene.exists():
            raise ValueError(f"the scene {args.scene} does not exist")
        if args.reference is not None and not args.reference.exists():
            raise ValueError(f"the reference {args.reference} does not exist")
        for d in args.define:
            if "=" not in d:
                raise ValueError(f"-D {d}: not name=value")
        args.output_dir.mkdir(parents=True, exist_ok=True)
        renders = render_methods(args, methods, args.output_dir)
        first = renders[methods[0]["label"]][0][0].image
        ref = load_reference(args.reference, first.shape) if args.reference else None
        results, pictures = compute_results(args, methods, renders, ref)
        write_report(args.output_dir, results, pictures)
    except (ValueError, runner.RenderError, OSError) as e:
        print(f"neepp compare: error: {e}", file=sys.stderr)
        return 1
    print(f"neepp compare: wrote {args.output_dir / 'index.html'} and {args.output_dir / 'results.json'}",
          file=sys.stderr)
    return 0


# The page: the numbers come from the embedded results (results.json), the images from data URIs.
PAGE = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>@TITLE@</title>
<style>
body { font-family: system-ui, sans-serif; margin: 1.5em; background: #fafafa; color: #222; }
h1 { font-size: 1.3em; } h2 { font-size: 1.1em; margin-top: 1.6em; }
table { border-collapse: collapse; font-size: 0.9em; } td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #eee; } td:first-child, th:first-child { text-align: left; }
.grid { display: flex; flex-wrap: wrap; gap: 0.8em; }
.grid figure { margin: 0; } .grid img { display: block; width: 240px; image-rendering: pixelated; cursor: pointer; }
figcaption { font-size: 0.8em; text-align: center; }
#viewer { position: relative; overflow: hidden; width: 100%; max-width: 960px; background: #000; cursor: grab; user-select: none; }
#stage { position: relative; transform-origin: 0 0; }
#stage img { display: block; width: 100%; image-rendering: pixelated; }
#stage #imgA { position: absolute; left: 0; top: 0; }
#split { position: absolute; top: 0; bottom: 0; width: 2px; background: #fff; pointer-events: none; }
.controls { margin: 0.5em 0; display: flex; gap: 1em; align-items: center; flex-wrap: wrap; }
.note { color: #666; font-size: 0.85em; }
</style></head><body>
<h1 id="title"></h1>
<p id="summary" class="note"></p>
<h2>Numbers</h2>
<table id="numbers"></table>
<p class="note">relMSE: mean of (I − R)² / (R² + 0.01) against the reference; relative variance: from two seeds;
mean FLIP: NVIDIA FLIP (HDR) against the reference; occlusion time: time inside shadow-ray queries.</p>
<h2>A/B viewer</h2>
<div class="controls">
 <label>A <select id="selA"></select></label>
 <label>B <select id="selB"></select></label>
 <label>show <select id="layer"></select></label>
 <label>split <input type="range" id="slider" min="0" max="100" value="50"></label>
 <button id="reset">reset zoom</button>
 <span class="note">wheel: zoom, drag: pan; A is left of the split, B right</span>
</div>
<div id="viewer"><div id="stage"><img id="imgB" alt="B"><img id="imgA" alt="A"></div><div id="split"></div></div>
<h2>Images</h2>
<div class="grid" id="images"></div>
<h2 id="errors-title">Relative error (per-pixel relMSE, log scale 1e-4 to 10)</h2>
<div class="grid" id="errors"></div>
<h2 id="flip-title">FLIP</h2>
<div class="grid" id="flips"></div>
<h2 id="plot-title">Convergence</h2>
<img id="plot" alt="relMSE against render time">
<pre id="selftest" hidden></pre>
<script type="application/json" id="results">@RESULTS@</script>
<script>
"use strict";
const R = JSON.parse(document.getElementById("results").textContent);
const IMAGES = @IMAGES@;
const PLOT = @PLOT@;
const LAYERS = {image: "image", error: "relative error", flip: "FLIP"};
function fmt(v, digits) {
  if (v === null || v === undefined) return "–";
  if (typeof v !== "number") return String(v);
  if (Number.isInteger(v)) return v.toLocaleString("en-US");
  return v.toPrecision(digits || 4);
}
document.getElementById("title").textContent = document.title;
document.getElementById("summary").textContent =
  `${R.mode}: ${R.spp ? R.spp + " spp" : R.time_s + " s"} per method, ${R.width}x${R.height}, ${R.seeds} seed(s); ` +
  `reference: ${R.reference || "none (no error metrics)"}; machine: ${R.machine.cpu || ""} ` +
  `(${R.machine.cores || "?"} cores, ${R.machine.simd || ""})` + (R.note ? "; " + R.note : "") +
  (R.credit ? ". Scene: " + R.credit : "");
const COLS = [["label", "method"], ["relmse", "relMSE"], ["rel_variance", "relative variance"], ["mean_flip", "mean FLIP"],
  ["spp", "spp"], ["render_time_s", "time (s)"], ["rays", "rays"], ["shadow_rays", "shadow rays"],
  ["occlusion_time_s", "occlusion time (s)"], ["image_mean", "image mean"]];
const table = document.getElementById("numbers");
const head = table.insertRow();
for (const [, name] of COLS) { const th = document.createElement("th"); th.textContent = name; head.appendChild(th); }
for (const m of R.methods) {
  const tr = table.insertRow();
  for (const [key] of COLS) { const td = tr.insertCell(); td.textContent = fmt(m[key]); td.dataset.key = key; td.dataset.value = JSON.stringify(m[key]); }
}
const labels = Object.keys(IMAGES);
const selA = document.getElementById("selA"), selB = document.getElementById("selB"), layerSel = document.getElementById("layer");
for (const l of labels) { selA.add(new Option(l, l)); selB.add(new Option(l, l)); }
selB.selectedIndex = labels.length > 1 ? 1 : 0;
for (const [k, name] of Object.entries(LAYERS)) if (labels.some(l => IMAGES[l][k])) layerSel.add(new Option(name, k));
function grid(id, layer) {
  const el = document.getElementById(id);
  let n = 0;
  for (const l of labels) {
    if (!IMAGES[l][layer]) continue;
    const f = document.createElement("figure"), img = document.createElement("img"), c = document.createElement("figcaption");
    img.src = IMAGES[l][layer]; img.alt = l; c.textContent = l;
    img.addEventListener("click", () => { selA.value = l; layerSel.value = layer; show(); });
    f.append(img, c); el.appendChild(f); ++n;
  }
  return n;
}
grid("images", "image");
if (!grid("errors", "error")) document.getElementById("errors-title").hidden = true;
if (!grid("flips", "flip")) document.getElementById("flip-title").hidden = true;
if (PLOT) document.getElementById("plot").src = PLOT; else { document.getElementById("plot").hidden = true; document.getElementById("plot-title").hidden = true; }
const imgA = document.getElementById("imgA"), imgB = document.getElementById("imgB"), slider = document.getElementById("slider");
const stage = document.getElementById("stage"), viewer = document.getElementById("viewer"), split = document.getElementById("split");
let zoom = 1, panX = 0, panY = 0;
function source(label, layer) { return IMAGES[label][layer] || IMAGES[label].image; }
function show() {
  imgA.src = source(selA.value, layerSel.value); imgB.src = source(selB.value, layerSel.value);
  const s = Number(slider.value);
  imgA.style.clipPath = `inset(0 ${100 - s}% 0 0)`;
  stage.style.transform = `translate(${panX}px, ${panY}px) scale(${zoom})`;
  split.style.left = `${panX + zoom * viewer.clientWidth * s / 100}px`;
}
for (const el of [selA, selB, layerSel]) el.addEventListener("change", show);
slider.addEventListener("input", show);
viewer.addEventListener("wheel", e => {
  e.preventDefault();
  const r = viewer.getBoundingClientRect(), x = e.clientX - r.left, y = e.clientY - r.top;
  const z = Math.min(32, Math.max(1, zoom * (e.deltaY < 0 ? 1.25 : 0.8)));
  panX = x - (x - panX) * z / zoom; panY = y - (y - panY) * z / zoom; zoom = z;
  if (zoom === 1) panX = panY = 0;
  show();
}, {passive: false});
let drag = null;
viewer.addEventListener("mousedown", e => { drag = [e.clientX - panX, e.clientY - panY]; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", e => { if (drag) { panX = e.clientX - drag[0]; panY = e.clientY - drag[1]; show(); } });
document.getElementById("reset").addEventListener("click", () => { zoom = 1; panX = panY = 0; show(); });
show();
// #selftest (the tests open the page so): every image decodes, the slider and zoom move the viewer, and
// the table holds the results' numbers; the verdict goes into the page's title and #selftest. Run at the
// load event, when every inlined image has loaded, and synchronously, so a headless browser's DOM dump
// (taken once the page has loaded) holds it.
const errors = [];
window.addEventListener("error", e => errors.push(String(e.message)));
if (location.hash === "#selftest") window.addEventListener("load", () => {
  const problems = [...document.images].filter(i => i.getAttribute("src") && !i.hidden && !(i.complete && i.naturalWidth > 0))
    .map(i => i.alt + ": does not decode").concat(errors);
  slider.value = 25; slider.dispatchEvent(new Event("input"));
  if (imgA.style.clipPath !== "inset(0px 75% 0px 0px)" && imgA.style.clipPath !== "inset(0 75% 0 0)") problems.push("slider did not move the split: " + imgA.style.clipPath);
  viewer.dispatchEvent(new WheelEvent("wheel", {deltaY: -1, clientX: 10, clientY: 10, cancelable: true}));
  if (!(zoom > 1)) problems.push("wheel did not zoom");
  const cells = table.querySelectorAll("td").length;
  if (cells !== R.methods.length * COLS.length) problems.push("table has " + cells + " cells");
  const out = document.getElementById("selftest");
  out.hidden = false;
  out.textContent = problems.length ? "selftest failed: " + problems.join("; ") : "selftest ok: " + document.images.length + " images";
  document.title = out.textContent;
  document.getElementById("reset").click(); slider.value = 50; show();
});
</script></body></html>
"""

if __name__ == "__main__":
    sys.exit(main())
