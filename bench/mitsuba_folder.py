#!/usr/bin/env python3
"""Every Mitsuba 3 scene under a folder, rendered by neepp and by Mitsuba 3 at low resolution: does it load,
and does neepp's image agree?

    .venv/bin/python bench/mitsuba_folder.py ~/mitsuba-tutorials/scenes
    .venv/bin/python bench/mitsuba_folder.py ~/scenes --size 96 --spp 128 --variant llvm_ad_rgb

A scene is every *.xml below the folder whose root is <scene>, except files another scene there
<include>s (fragments). Each is rendered as published: its own integrator, sensor and sampler, only the
resolution lowered and the sample count set. The resolution: where the scene declares `resx`/`resy`
defaults they are passed as -D values; otherwise a copy of the file beside it (.lowres_NAME.xml,
removed afterwards) gets a film whose largest side is --size, aspect ratio kept (crop windows scaled with
it). Both renderers get that same file and --spp.

Columns: loads (or neepp's first error), Mitsuba's own status, neepp's mean over Mitsuba's (sum of RGB),
relMSE of neepp's image against Mitsuba's (both noisy, so it has a floor of about twice one render's
relative variance) and the times. Writes bench/out/mitsuba_folder/ (git-ignored): images, results.json,
table.md.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from mitsuba_suite import first_error, included_files  # noqa: E402
from neepp_tools import metrics, report, runner  # noqa: E402

DEFAULT_FILM = (768, 576)  # Mitsuba 3's hdrfilm when the scene gives no size


def scenes_under(folder: Path) -> list[Path]:
    """The scene files below folder: XML files whose root element is <scene> and that no other scene
    file there includes."""
    candidates = []
    for f in sorted(folder.rglob("*.xml")):
        if f.name.startswith(".lowres_"):
            continue
        try:
            if ET.parse(f).getroot().tag == "scene":
                candidates.append(f.resolve())
        except ET.ParseError:
            candidates.append(f.resolve())  # a renderer will say what is wrong with it
    included = {g for f in candidates for g in included_files(f)[1:]}
    return [f for f in candidates if f not in included]


def scaled_size(width: int, height: int, size: int) -> tuple[int, int]:
    s = min(1.0, size / max(width, height))
    return max(1, round(width * s)), max(1, round(height * s))


def sensor_chain(scene: Path, seen=None) -> list[tuple[Path, ET.Element, ET.Element | None]] | None:
    """[(file, its parsed root, the <include> element that leads on)] from the scene down to the file
    whose top level declares the first <sensor>, or None when no file does."""
    seen = seen if seen is not None else set()
    if scene in seen or not scene.is_file():
        return None
    seen.add(scene)
    try:
        root = ET.parse(scene).getroot()
    except ET.ParseError:
        return None
    for e in root:
        if e.tag == "sensor":
            return [(scene, root, None)]
        if e.tag == "include" and e.get("filename"):
            rest = sensor_chain((scene.parent / e.get("filename")).resolve(), seen)
            if rest:
                return [(scene, root, e)] + rest
    return None


def uses_parameter(scene: Path, name: str) -> bool:
    pattern = re.compile(r"\$" + re.escape(name) + r"\b")
    return any(pattern.search(f.read_text(errors="replace")) for f in included_files(scene.resolve()))


def all_defaults(scene: Path) -> dict[str, str]:
    out = {}
    for f in included_files(scene.resolve()):
        try:
            for d in ET.parse(f).getroot().iter("default"):
                out.setdefault(d.get("name"), d.get("value"))
        except ET.ParseError:
            pass
    return out


def low_resolution(scene: Path, size: int) -> tuple[Path, dict, str, list[Path]]:
    """(file to render, -D values, what was done, copies to remove afterwards). Where the scene declares
    resx/resy defaults they become -D values, as does a parameter the film's width or height names;
    otherwise the film of the first sensor (in the scene or a file it includes) is rewritten in copies
    (.lowres_NAME.xml beside each file on the way to it) to at most `size` pixels on its largest side."""
    defaults = all_defaults(scene)
    if "resx" in defaults and "resy" in defaults:
        w, h = scaled_size(int(defaults["resx"]), int(defaults["resy"]), size)
        return scene, {"resx": w, "resy": h}, f"-D resx={w} resy={h}", []
    chain = sensor_chain(scene.resolve())
    if not chain:
        return scene, {}, "no sensor found: as published", []
    sensor = chain[-1][1].find("sensor")
    film = sensor.find("film")
    if film is None:
        film = ET.SubElement(sensor, "film", {"type": "hdrfilm"})
    props = {e.get("name"): e for e in film.findall("integer")}

    def current(name, fallback):
        e = props.get(name)
        if e is None:
            return fallback
        v = e.get("value", "")
        return int(defaults.get(v[1:], fallback)) if v.startswith("$") else int(v)

    w, h = current("width", DEFAULT_FILM[0]), current("height", DEFAULT_FILM[1])
    nw, nh = scaled_size(w, h, size)
    defines = {}
    for name, v in (("width", nw), ("height", nh)):
        e = props.get(name)
        if e is None:
            ET.SubElement(film, "integer", {"name": name, "value": str(v)})
        elif e.get("value", "").startswith("$"):
            defines[e.get("value")[1:]] = v
        else:
            e.set("value", str(v))
    for name, e in props.items():
        if name.startswith("crop_") and not e.get("value", "").startswith("$"):
            e.set("value", str(max(0 if "offset" in name else 1, int(int(e.get("value")) * nw / w))))
    copies = [f.with_name(f".lowres_{f.name}") for f, _, _ in chain]
    for (f, root, include), copy, nxt in zip(chain, copies, copies[1:] + [None]):
        if include is not None:
            include.set("filename", str(Path(include.get("filename")).with_name(nxt.name)))
        ET.ElementTree(root).write(copy, encoding="unicode")
    return copies[0], defines, f"film {nw}x{nh}" + (f" (-D {defines})" if defines else ""), copies


def brief(error: str) -> str:
    """An error for the table: without the list of what is supported."""
    return re.sub(r" \(supported: [^)]*\)", "", error)


def compare(img, ref) -> dict:
    mref = float(np.sum(ref[..., :3], dtype=np.float64))
    return {"mean_ratio": float(np.sum(img[..., :3], dtype=np.float64)) / mref if mref else float("nan"),
            "relmse": metrics.relmse(img, ref)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder")
    ap.add_argument("--scenes", default="", help="comma-separated substrings of the scene paths to run")
    ap.add_argument("--size", type=int, default=128, help="largest side of the film, in pixels")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--variant", default="", help="Mitsuba 3 variant (default llvm_ad_rgb where libLLVM is there: "
                    "it has the differentiable integrators scalar_rgb lacks; else scalar_rgb)")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=900, help="seconds per render")
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "mitsuba_folder"))
    a = ap.parse_args(argv)
    a.variant = a.variant or ("llvm_ad_rgb" if runner.mitsuba_available("llvm_ad_rgb")[0] else "scalar_rgb")
    folder = Path(a.folder).expanduser().resolve()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)

    results = []
    wanted = [w for w in a.scenes.split(",") if w]
    for scene in scenes_under(folder):
        if wanted and not any(w in str(scene.relative_to(folder)) for w in wanted):
            continue
        rec = render_both(scene, folder, a, out)
        results.append(rec)
        print(json.dumps(rec), flush=True)

    table = report.markdown_table([table_row(r) for r in results])
    summary = summary_of(results) + f" ({a.spp} spp, largest side {a.size}, Mitsuba {a.variant})"
    (out / "results.json").write_text(json.dumps(results, indent=2))
    (out / "table.md").write_text(table + "\n\n" + summary + "\n")
    print(table)
    print(summary)
    return 0


def render_both(scene: Path, folder: Path, a, out: Path) -> dict:
    """The scene's record: whether each renderer loads it (or its first error), and how the images compare."""
    name = str(scene.relative_to(folder))
    stem = re.sub(r"[^\w.-]", "_", name[:-4])
    target, defines, how, copies = low_resolution(scene, a.size)
    if uses_parameter(scene, "spp"):  # some scenes expect it from the command line, with no default
        defines["spp"] = a.spp
    rec = {"scene": name, "resolution": how}

    def error(e):  # the copies' names are the originals' with a prefix
        return first_error(str(e), target.parent).replace(".lowres_", "")

    neepp_img = mitsuba_img = None
    try:
        try:
            r = runner.run_neepp(target, out / f"{stem}_neepp.exr", spp=a.spp, seed=1, defines=defines,
                                 threads=a.threads or None, timeout=a.timeout)
            neepp_img = r.image
            rec.update(loads="yes", neepp_s=r.wall_s)
        except runner.RenderError as e:
            rec["loads"] = error(e)
        try:
            m = runner.run_mitsuba(target, out / f"{stem}_mitsuba.exr", variant=a.variant, spp=a.spp, seed=0,
                                   defines=defines, threads=a.threads, timeout=a.timeout, as_published=True)
            mitsuba_img = m.image
            rec.update(mitsuba="yes", mitsuba_s=m.wall_s)
        except runner.RenderError as e:
            rec["mitsuba"] = error(e)
    finally:
        for c in copies:
            c.unlink(missing_ok=True)
    if neepp_img is not None and mitsuba_img is not None:
        if neepp_img.shape == mitsuba_img.shape:
            rec.update(compare(neepp_img, mitsuba_img))
        else:
            rec["note"] = f"sizes differ: neepp {neepp_img.shape[:2]}, Mitsuba {mitsuba_img.shape[:2]}"
    return rec


def table_row(rec: dict) -> dict:
    def num(key, digits):
        return f"{rec[key]:.{digits}f}" if key in rec else None

    return {"scene": rec["scene"], "loads": brief(rec["loads"]), "Mitsuba 3": brief(rec["mitsuba"]),
            "mean ratio": num("mean_ratio", 4) or rec.get("note"), "relMSE": num("relmse", 4),
            "neepp s": num("neepp_s", 1), "Mitsuba s": num("mitsuba_s", 1), "resolution": rec["resolution"]}


def summary_of(results: list[dict]) -> str:
    both = [r for r in results if "mean_ratio" in r]
    return (f"{len(results)} scenes: neepp loads {sum(r['loads'] == 'yes' for r in results)}, Mitsuba 3 "
            f"{sum(r['mitsuba'] == 'yes' for r in results)}; of the {len(both)} both render, "
            f"{sum(abs(r['mean_ratio'] - 1) <= 0.02 for r in both)} have the mean within 2 %")


if __name__ == "__main__":
    sys.exit(main())
