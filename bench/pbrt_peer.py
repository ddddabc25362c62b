#!/usr/bin/env python3
"""neepp against a second peer renderer, pbrt-v4: path tracing and BDPT speed and image means.

For each scene (default cornell-box and veach-ajar) and integrator pair

    path : neepp --integrator path  vs pbrt-v4 "path" (unidirectional, next event estimation + MIS;
           pbrt's light sampler is its default "bvh", --pbrt-lightsampler changes it)
    bdpt : neepp --integrator bdpt  vs pbrt-v4 "bdpt" (its light sampler is always "power")

both renderers render the same camera at the same resolution (the scene's own film size divided by
--scale), the same maximum path length, the same spp, a box pixel filter of radius 0.5 pixel, independent
random numbers and the same number of threads (pbrt --nthreads), taking turns to go first, --rounds times
with different seeds (pbrt --seed). The table gives each renderer's render time (scene loading and
acceleration-structure build excluded: neepp's stats `render_time_s`; pbrt-v4's "renderTimeSeconds"
attribute that it writes into the EXR header, the time its ImageTileIntegrator::Render spent from the start
of the first sample to the last, after parsing, the BVH and the light sampler are built; its progress bar
shows the same number to 0.1 s), samples/s = pixels*spp / render time, the neepp/pbrt ratio of each round's
pair (median; metrics.paired_ratios; also the ratio of samples per CPU second of the render, which others'
load disturbs less), and the image means (R, G, B, Rec. 709 luminance) of both renderers (all rounds
averaged) and of the Mitsuba 3 reference in ../shared/scenes/<scene>/reference/, and each renderer's relMSE
against the reference (box-downsampled to the render's resolution; median over rounds) with the efficiency
ratio (relMSE x time of pbrt over neepp's). pbrt-v4 renders spectrally (4 wavelengths a sample, RGB
reflectances and emission uplifted), neepp in RGB: the same scene gives slightly different means.

Path length. neepp takes Mitsuba 3's max_depth: the number of path segments, max_depth=2 is direct light.
pbrt-v4's maxdepth counts bounces: its path tracer stops at `depth++ == maxDepth` after adding emission,
before the next light sample, so maxdepth 0 is the emitters seen directly and 1 direct lighting; its BDPT
keeps strategies with s + t - 2 <= maxdepth, i.e. segments - 1. So pbrt maxdepth = max_depth - 1
(--check-depth renders max_depth 1..4 with both integrators of both renderers to show it).

Load: as bench/tungsten_peer.py (bench/peer_rounds.py, which both use): a round whose render saw more than
--max-other-load cores used by others is run again (--retries), --wait-quiet S waits for a quiet machine.

pbrt-v4's scenes. --pbrt-scenes DIR holds <scene>/pbrt/scene-v4.pbrt and its models/ and textures/: the
layout of the public repository gonsolo/bitterli (Bitterli's scenes in pbrt-v4 format; the files carry
gonsolo's edits of spp, resolution and depth, which this script replaces). The script writes a copy: its own
Integrator, Sampler, PixelFilter and Film, the file's camera (Transform and Camera kept), the rest
(WorldBegin on) with absolute paths, and per-scene edits so that the scene is the Mitsuba scene.xml that
neepp renders (SCENE_EDITS: a texture the repository lacks is taken from the Mitsuba scene's textures/, an
environment map is the Mitsuba one converted to pbrt-v4's equal-area square with pbrt's imgtool
makeequiarea and oriented by the Mitsuba to_world, materials that differ are made equal where pbrt-v4 has
the same model). Nothing of pbrt-v4 or of the scenes is kept in this repository.

All six evaluation scenes load and render with both integrators. Not equal, and left so: pbrt-v4 has no
Mitsuba plastic/roughplastic, Bitterli's files use its layered "coateddiffuse" (a random walk in the
coating) instead; its conductors are GGX only (veach-ajar's door handle is Beckmann in Mitsuba); the mirrors
(Mitsuba's perfect "none" conductor) are silver; living-room's leaves are "diffusetransmission" in pbrt, a
masked diffuse in Mitsuba. Image means against the reference (luminance, pbrt/ref; path and bdpt at 4 spp,
scale 8, so a percent or two of noise): cornell-box 0.985 / 0.993, veach-ajar 0.99 / 1.00 (bdpt at 64 spp:
1.002), bathroom 0.988 / 0.985, classroom 0.97 / 1.00, staircase 0.97 / 0.985, living-room 1.01 / 1.01.
staircase's red is 5-6 % low: the difference grows with the bounces through its saturated wood textures
(0.976 in red at max_depth 2), i.e. pbrt's spectral rendering, and a longer coateddiffuse random walk does not
change it. cornell-box's blue is 7 % low in pbrt: its light's RGB (17, 12, 4) is uplifted to a spectrum.

Building pbrt-v4 (only for this measurement; never commit it or its scenes):

    # the public repository mmp/pbrt-v4 (tested at 5f7a606) with its submodules in src/ext (ptex,
    # double-conversion, stb, openexr, filesystem, openvdb, libdeflate, lodepng, utf8proc, qoi, glfw, zlib) at
    # the commits it pins (tested: zlib and double-conversion at their newest, cc1f75a and d201f04), e.g. in
    # /work/peers/pbrt-v4, and gonsolo/bitterli (tested at dc0bfae) in /work/peers/bitterli
    cd /work/peers/pbrt-v4 && mkdir build && cd build
    cmake -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF -DGLFW_BUILD_X11=OFF -DGLFW_BUILD_WAYLAND=OFF ..
    make -j2 pbrt_exe imgtool          # ./pbrt and ./imgtool (imgtool: environment-map conversion)
    # PBRT_BUILD_NATIVE_EXECUTABLE is ON by default: pbrt is compiled with -march=native (the host's vector
    # units; -DPBRT_BUILD_NATIVE_EXECUTABLE=OFF for a generic build). pbrt has no GPU switch (PBRT_USE_GPU is
    # no option of it): it builds its GPU renderer only when CMake finds a CUDA compiler; none here.
    # Debian 12's OpenEXR 3.1.5 (libopenexr-dev) is found and used, so src/ext/openexr is not built. pbrt
    # always builds GLFW for its interactive viewer: X11 and Wayland off leaves GLFW's null platform, which
    # needs no X11/Wayland development packages (pbrt --interactive then cannot open a window).
    # BUILD_TESTING=OFF: otherwise double-conversion's own tests are configured too. It builds with GCC 12.
    # The copy tested lacked src/pbrt/util/bluenoise.cpp and pmj02tables.cpp (tables of several MB, absent
    # from the snapshot it came from): two files defining the same arrays zero-filled stood in. Only the
    # pmj02bn sampler and 8-bit dithering read them; this script uses the independent sampler and EXR output.

    .venv/bin/python bench/pbrt_peer.py --pbrt /work/peers/pbrt-v4/build/pbrt \\
        --pbrt-scenes /work/peers/bitterli --wait-quiet 900
    .venv/bin/python bench/pbrt_peer.py ... --scenes cornell-box --pairs path --rounds 1 --spp 4 --scale 8
    .venv/bin/python bench/pbrt_peer.py ... --check-depth                        # max_depth mapping check

Writes bench/out/pbrt_peer/ (git-ignored): report.md, results.json, the generated pbrt scenes, the images
(EXR) and per scene/pair a side-by-side PNG (neepp | pbrt | reference).
"""
from __future__ import annotations

import argparse
import json
import re
import shlex
import struct
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))
sys.path.insert(0, str(REPO / "bench"))

from neepp_tools import SCENES_DIR, credit, exr, machine, report, runner  # noqa: E402
from peer_rounds import channel_means, luminance, run_rounds, summarize_rounds  # noqa: E402
from tungsten_peer import scene_film  # noqa: E402

#: name: (neepp integrator, pbrt-v4 integrator)
PAIRS = {"path": ("path", "path"), "bdpt": ("bdpt", "bdpt")}
#: spp per scene and pair: pbrt-v4's render about 15-50 s with 2 threads at scale 4 (neepp's 3-9 times less);
#: other scenes take the pair's entry under None
DEFAULT_SPP = {("cornell-box", "path"): 64, (None, "path"): 32, ("cornell-box", "bdpt"): 16, (None, "bdpt"): 8}
#: pbrt-v4 maxdepth = Mitsuba max_depth - 1 (bounces against segments); --check-depth shows it
DEPTH_OFFSET = 1


# ----------------------------------------------------------------------------------------------
# pbrt-v4 scene files

_TOKEN = re.compile(r'"[^"]*"|#[^\n]*|\[|\]|[^\s\[\]"#]+')
#: header directives kept from the scene file (the camera); the others (Integrator, Sampler, Film,
#: PixelFilter, Accelerator, ...) are replaced
_KEEP = {"LookAt", "Transform", "ConcatTransform", "Scale", "Translate", "Rotate", "Identity",
         "CoordinateSystem", "CoordSysTransform", "Camera"}


def split_pbrt(text: str) -> tuple[list[list[str]], str]:
    """(directives before WorldBegin as token lists, comments dropped; the text from WorldBegin on)."""
    directives = []
    for m in _TOKEN.finditer(text):
        tok = m.group(0)
        if tok.startswith("#"):
            continue
        if tok == "WorldBegin":
            return directives, text[m.start():]
        if re.fullmatch(r"[A-Z][A-Za-z]*", tok):
            directives.append([tok])
        elif directives:
            directives[-1].append(tok)
        else:
            raise ValueError(f"pbrt file: parameter {tok!r} before any directive")
    raise ValueError("pbrt file: no WorldBegin")


def pbrt_header(directives: list[list[str]], *, integrator: str, maxdepth: int, spp: int, res: tuple[int, int],
                out_exr: Path, lightsampler: str | None) -> str:
    integ = f'Integrator "{integrator}" "integer maxdepth" [ {maxdepth} ]'
    if lightsampler and integrator == "path":
        integ += f' "string lightsampler" "{lightsampler}"'
    lines = [integ,
             f'Sampler "independent" "integer pixelsamples" [ {spp} ]',
             'PixelFilter "box" "float xradius" [ 0.5 ] "float yradius" [ 0.5 ]',
             f'Film "rgb" "string filename" [ "{out_exr}" ] "integer xresolution" [ {res[0]} ] '
             f'"integer yresolution" [ {res[1]} ]']
    kept = [" ".join(d) for d in directives if d[0] in _KEEP]
    if not any(d.startswith("Camera") for d in kept):
        raise ValueError("pbrt file: no Camera before WorldBegin")
    return "\n".join(lines + kept) + "\n"


def _envmap_transform(to_world: np.ndarray) -> str:
    """pbrt-v4 Transform (world from light) of an infinite light showing a Mitsuba envmap with to_world.

    Mitsuba looks up direction v (envmap space, y up) at u = atan2(v.x, -v.z)/2pi, v = acos(v.y)/pi; pbrt-v3's
    lat-long maps, which imgtool makeequiarea reads, are phi/2pi, theta/pi about z. The same texel is pbrt's
    d = (x, y, z) and Mitsuba's P d = (y, z, -x), so world from light = to_world P."""
    p = np.array([[0, 1, 0, 0], [0, 0, 1, 0], [-1, 0, 0, 0], [0, 0, 0, 1]], dtype=float)
    m = to_world @ p
    return "Transform [ " + " ".join(f"{x:.9g}" for x in m.T.reshape(-1)) + " ]"  # pbrt: column after column


def _mitsuba_matrix(el: ET.Element | None) -> np.ndarray:
    if el is None:
        return np.eye(4)
    mat = el.find("matrix")
    if mat is None or len(el) != 1:
        raise ValueError("envmap to_world: only a single <matrix> is converted")
    return np.array([float(x) for x in re.split(r"[,\s]+", mat.get("value").strip())]).reshape(4, 4)


def convert_envmap(imgtool: Path, xml: Path, work: Path) -> tuple[Path, str, float]:
    """The Mitsuba scene's envmap as a pbrt-v4 equal-area EXR; (file, Transform line, scale)."""
    em = ET.parse(xml).getroot().find("emitter")
    if em is None or em.get("type") != "envmap":
        raise ValueError(f"{xml}: no scene-level envmap")
    props = {c.get("name"): c for c in em}
    src = (xml.parent / props["filename"].get("value")).resolve()
    scale = float(props["scale"].get("value")) if "scale" in props else 1.0
    out = work / (src.stem.replace(" ", "_") + "_equiarea.exr")
    if not out.exists():
        work.mkdir(parents=True, exist_ok=True)
        r = subprocess.run([str(imgtool), "makeequiarea", str(src), "--outfile", str(out)], capture_output=True,
                           text=True)
        if r.returncode != 0 or not out.exists():
            raise runner.RenderError(f"imgtool makeequiarea failed: {r.stdout}{r.stderr}")
    return out, _envmap_transform(_mitsuba_matrix(props.get("to_world"))), scale


def _directive_spans(text: str, name: str, kind: str | None = None) -> list[tuple[int, int]]:
    """Character spans of each `name` directive (with its parameters) in text; kind: its first string."""
    toks = [m for m in _TOKEN.finditer(text) if not m.group(0).startswith("#")]
    spans = []
    for i, m in enumerate(toks):
        if m.group(0) != name or (kind and (i + 1 >= len(toks) or toks[i + 1].group(0) != f'"{kind}"')):
            continue
        j = i + 1
        while j < len(toks) and not re.fullmatch(r"[A-Z][A-Za-z]*", toks[j].group(0)):
            j += 1
        spans.append((m.start(), toks[j - 1].end()))
    return spans


def remove_directives(text: str, name: str, kind: str | None = None) -> tuple[str, int]:
    spans = _directive_spans(text, name, kind)
    for a, b in reversed(spans):
        text = text[:a] + f"# (removed {name} {kind or ''})" + text[b:]
    return text, len(spans)


def replace_material(body: str, name: str, new: str) -> str:
    """Replace the MakeNamedMaterial `name` block by the text `new`."""
    spans = _directive_spans(body, "MakeNamedMaterial", name)
    if len(spans) != 1:
        raise ValueError(f"material {name}: {len(spans)} definitions")
    a, b = spans[0]
    return body[:a] + new + body[b:]


class SceneContext:
    def __init__(self, scene: str, args, work: Path):
        self.scene, self.args, self.work = scene, args, work
        self.xml = Path(args.scenes_dir) / scene / "scene.xml"
        self.pbrt_dir = Path(args.pbrt_scenes) / scene / "pbrt"
        self.notes: list[str] = []

    def resolve(self, name: str) -> str:
        """A file named in the pbrt scene, absolute; a texture missing there is taken from the Mitsuba scene."""
        p = self.pbrt_dir / name
        if p.exists():
            return str(p.resolve())
        stem = Path(name).stem
        for cand in sorted((self.xml.parent / Path(name).parent).glob(glob_escape(stem) + ".*")):
            self.notes.append(f"{name} (absent) -> Mitsuba's {cand.name}")
            return str(cand.resolve())
        raise FileNotFoundError(f"{p} (and no {stem}.* in {self.xml.parent / Path(name).parent})")

    def envmap(self) -> str:
        """An infinite light block equal to the Mitsuba scene's envmap."""
        f, transform, scale = convert_envmap(Path(self.args.imgtool), self.xml, self.work.parent / "envmaps")
        self.notes.append(f"infinite light = Mitsuba envmap converted by imgtool makeequiarea ({f.name})")
        return (f'AttributeBegin\n    {transform}\n    LightSource "infinite" "string filename" [ "{f}" ] '
                f'"float scale" [ {scale} ]\nAttributeEnd\n')


def glob_escape(s: str) -> str:
    return re.sub(r"([*?\[])", r"[\1]", s)


def _edit_lights_to_envmap(body: str, ctx: SceneContext) -> str:
    """Replace the file's distant/infinite lights by the Mitsuba scene's envmap."""
    n = 0
    for kind in ("infinite", "distant"):
        body, k = remove_directives(body, "LightSource", kind)
        if k:
            ctx.notes.append(f"removed {k} LightSource \"{kind}\"")
        n += k
    head, rest = body.split("WorldBegin", 1)
    return head + "WorldBegin\n" + ctx.envmap() + rest


def _edit_veach_ajar_floor(body: str, ctx: SceneContext) -> str:
    """Mitsuba's floor is the rough conductor times a checkerboard specular_reflectance (0.8 / 0.2, to_uv scale
    20 x 80: squares of 1/40 x 1/160 in uv); pbrt's has no checkerboard. pbrt-v4's conductor takes no
    reflectance factor, so a "mix" of it and black, choosing the conductor with probability = the checkerboard,
    gives the same expected value. Squares: Mitsuba's color0 (0.8) where floor(40 u) + floor(160 v') is even,
    v' = 1 - v (it flips an OBJ's v; pbrt reads the same uv from the PLY unflipped); floor(160 (1 - v)) =
    159 - floor(160 v) turns the parity over, so pbrt's tex2 (odd squares) is 0.8."""
    spans = _directive_spans(body, "MakeNamedMaterial", "Floor")
    if len(spans) != 1:
        raise ValueError("veach-ajar: no single Floor material")
    metal = body[spans[0][0]:spans[0][1]].replace('"Floor"', '"FloorMetal"', 1)
    new = (metal + '\nMakeNamedMaterial "FloorBlack" "string type" [ "diffuse" ] "rgb reflectance" [ 0 0 0 ]\n'
           'Texture "FloorChecks" "float" "checkerboard" "float uscale" [ 40 ] "float vscale" [ 160 ] '
           '"float tex1" [ 0.2 ] "float tex2" [ 0.8 ]\n'
           'MakeNamedMaterial "Floor" "string type" [ "mix" ] "string materials" [ "FloorBlack" "FloorMetal" ] '
           '"texture amount" "FloorChecks"')
    ctx.notes.append("Floor: conductor x checkerboard 0.8/0.2 (mix with black), as Mitsuba's")
    return replace_material(body, "Floor", new)


def _edit_bathroom_rug(body: str, ctx: SceneContext) -> str:
    """The Mitsuba scene's rug is a constant grey 0.55 (its rug texture was not available, nor is it here)."""
    body, n = remove_directives(body, "Texture", "Texture01")
    if n != 1:
        raise ValueError("bathroom: no rug texture Texture01")
    ctx.notes.append("Rug: grey 0.55 as in the Mitsuba scene (rug.tga absent in both)")
    return replace_material(body, "Rug", 'MakeNamedMaterial "Rug" "string type" [ "diffuse" ] '
                                         '"rgb reflectance" [ 0.55 0.55 0.55 ]')


def _edit_specular_reflectance(body: str, ctx: SceneContext) -> str:
    """Mitsuba conductors with a grey specular_reflectance g < 1 (window and chair frames, brushed steel):
    pbrt-v4's conductor has no such factor (Bitterli's pbrt files drop it), so the material becomes a "mix"
    choosing it with probability g and black otherwise: the same expected value."""
    for el in ET.parse(ctx.xml).getroot().iter("bsdf"):
        bid, inner = el.get("id"), el
        if not bid:
            continue
        while inner is not None and inner.get("type") in ("twosided", "bumpmap", "mask"):
            inner = inner.find("bsdf")
        if inner is None or inner.get("type") not in ("conductor", "roughconductor"):
            continue
        sr = inner.find("rgb[@name='specular_reflectance']")
        if sr is None:
            continue
        v = [float(x) for x in re.split(r"[,\s]+", sr.get("value").strip()) if x]
        v = v * 3 if len(v) == 1 else v
        if min(v) > 1 - 1e-6:
            continue
        name = bid[:-4] if bid.endswith("BSDF") else bid
        spans = _directive_spans(body, "MakeNamedMaterial", name)
        if len(spans) != 1 or max(v) - min(v) > 1e-6:
            ctx.notes.append(f"{name}: specular_reflectance {v} not applied")
            continue
        a, b = spans[0]
        metal = body[a:b].replace(f'"{name}"', f'"{name}_metal"', 1)
        new = (f'{metal}\nMakeNamedMaterial "{name}_black" "string type" [ "diffuse" ] "rgb reflectance" [ 0 0 0 ]\n'
               f'MakeNamedMaterial "{name}" "string type" [ "mix" ] "string materials" [ "{name}_black" '
               f'"{name}_metal" ] "float amount" [ {v[0]} ]')
        body = body[:a] + new + body[b:]
        ctx.notes.append(f"{name}: conductor x specular_reflectance {v[0]} (mix with black)")
    return body


#: per scene: edits that make gonsolo/bitterli's pbrt-v4 file the Mitsuba scene.xml neepp renders
SCENE_EDITS: dict[str, list] = {
    "veach-ajar": [_edit_veach_ajar_floor],
    "bathroom": [_edit_bathroom_rug, _edit_specular_reflectance],
    "classroom": [_edit_lights_to_envmap, _edit_specular_reflectance],
    "staircase": [_edit_specular_reflectance],
    "living-room": [_edit_lights_to_envmap, _edit_specular_reflectance],
}


def pbrt_scene(scene: str, args, work: Path, *, integrator: str, max_depth: int, spp: int,
               res: tuple[int, int], out_exr: Path, name: str) -> tuple[Path, list[str]]:
    """Write work/<name>.pbrt for the scene; (path, notes on what was changed)."""
    ctx = SceneContext(scene, args, work)
    src = ctx.pbrt_dir / "scene-v4.pbrt"
    if not src.exists():
        raise FileNotFoundError(f"{src}: no pbrt-v4 version of {scene}")
    directives, body = split_pbrt(src.read_text(errors="replace"))
    for edit in SCENE_EDITS.get(scene, []):
        body = edit(body, ctx)
    body = re.sub(r'("string filename"\s*\[?\s*")([^"]*)(")',
                  lambda m: m.group(1) + (m.group(2) if m.group(2).startswith("/") else ctx.resolve(m.group(2)))
                  + m.group(3), body)
    header = pbrt_header(directives, integrator=integrator, maxdepth=max_depth - DEPTH_OFFSET, spp=spp, res=res,
                         out_exr=out_exr, lightsampler=args.pbrt_lightsampler)
    work.mkdir(parents=True, exist_ok=True)
    path = work / f"{name}.pbrt"
    path.write_text(f"# generated by bench/pbrt_peer.py from {src}\n" + header + body)
    return path, list(dict.fromkeys(ctx.notes))


# ----------------------------------------------------------------------------------------------
# running pbrt-v4


def exr_float_attribute(path: Path, name: str) -> float | None:
    """A float attribute of an EXR header (pbrt-v4 writes renderTimeSeconds there)."""
    with open(path, "rb") as f:
        data = f.read(1 << 16)
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an EXR file")
    off = 8
    while off < len(data) and data[off] != 0:
        a = data.index(b"\0", off)
        attr = data[off:a].decode("latin-1")
        b = data.index(b"\0", a + 1)
        typ = data[a + 1:b].decode("latin-1")
        (size,) = struct.unpack_from("<i", data, b + 1)
        val = b + 5
        if attr == name and typ == "float":
            return struct.unpack_from("<f", data, val)[0]
        off = val + size
    return None


def run_pbrt(binary: Path, scene_file: Path, out_exr: Path, *, threads: int, seed: int, timeout: float = 7200) -> dict:
    if out_exr.exists():
        out_exr.unlink()
    cmd = [str(binary), "--nthreads", str(threads), "--seed", str(seed), "--quiet", str(scene_file)]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=scene_file.parent)
    wall = time.perf_counter() - t0
    log = r.stdout + r.stderr
    if r.returncode != 0 or not out_exr.exists():
        raise runner.RenderError(f"pbrt failed (rc={r.returncode}): {shlex.join(cmd)}\n{log[-4000:]}")
    t = exr_float_attribute(out_exr, "renderTimeSeconds")
    if t is None:
        raise runner.RenderError(f"{out_exr}: no renderTimeSeconds attribute")
    return {"image": exr.read_exr(out_exr), "render_time_s": float(t), "wall_s": wall, "log": log}


# ----------------------------------------------------------------------------------------------


def render_pair(who: str, scene: str, pair: str, args, work: Path, tag: str, *, res, spp: int, max_depth: int,
                seed: int) -> dict:
    """One render by `who` ("neepp" or "pbrt"); image, render time, wall time, notes."""
    neepp_integrator, pbrt_integrator = PAIRS[pair]
    if who == "neepp":
        xml = Path(args.scenes_dir) / scene / "scene.xml"
        res_ = runner.run_neepp(xml, work / f"neepp_{tag}.exr", spp=spp, resx=res[0], resy=res[1],
                                max_depth=max_depth, seed=seed, threads=args.threads, integrator=neepp_integrator,
                                extra_args=["--rfilter", "box"], timeout=7200)
        return {"image": res_.image, "render_time_s": float(res_.stats["render_time_s"]), "wall_s": res_.wall_s,
                "notes": []}
    out_exr = work / f"pbrt_{tag}.exr"
    sf, notes = pbrt_scene(scene, args, work, integrator=pbrt_integrator, max_depth=max_depth, spp=spp, res=res,
                           out_exr=out_exr, name=f"pbrt_{tag}")
    r = run_pbrt(Path(args.pbrt), sf, out_exr, threads=args.threads, seed=seed)
    r["notes"] = notes
    return r


def measure(scene: str, pair: str, args, out: Path) -> dict:
    xml = Path(args.scenes_dir) / scene / "scene.xml"
    W, H = scene_film(xml)
    w, h = W // args.scale, H // args.scale
    spp = args.spp or DEFAULT_SPP.get((scene, pair), DEFAULT_SPP[(None, pair)])
    work = out / scene / pair
    work.mkdir(parents=True, exist_ok=True)
    notes: list[str] = []

    def render(who: str, r: int, seed: int) -> dict:
        nonlocal notes
        q = render_pair(who, scene, pair, args, work, f"r{r}", res=(w, h), spp=spp, max_depth=args.max_depth,
                        seed=seed)
        notes = q.pop("notes") or notes
        return q

    rounds, attempts = run_rounds(args, scene, pair, "pbrt", w * h, spp, render)
    summary, img_n, img_p, ref_small = summarize_rounds(args, scene, "pbrt", rounds, w, h)
    row = {"scene": scene, "pair": pair, "res": f"{w}x{h}", "max_depth": args.max_depth,
           "pbrt maxdepth": args.max_depth - DEPTH_OFFSET, "spp": spp, "rounds": len(rounds), **summary,
           "pbrt scene": str(Path(args.pbrt_scenes) / scene / "pbrt" / "scene-v4.pbrt"), "scene edits": notes,
           "attempts": attempts}
    exr.write_exr(work / "neepp_mean.exr", img_n)
    exr.write_exr(work / "pbrt_mean.exr", img_p)
    report.comparison_figure(work / "compare.png", {"neepp": img_n, "pbrt-v4": img_p}, ref=ref_small,
                             title=f"{scene} {pair}: {w}x{h}, {spp} spp x {len(rounds)}, max_depth {args.max_depth}",
                             credit=credit(scene))
    return row


def check_depth(args, out: Path) -> list[dict]:
    """Image means at max_depth 1..4 (neepp) against pbrt maxdepth 0..3, both pairs, the first scene."""
    scene = args.scenes.split(",")[0]
    W, H = scene_film(Path(args.scenes_dir) / scene / "scene.xml")
    res = (W // (2 * args.scale), H // (2 * args.scale))
    spp = args.spp or 64
    work = out / scene / "depth"
    rows = []
    for d in (1, 2, 3, 4):
        row = {"neepp max_depth": d, "pbrt maxdepth": d - DEPTH_OFFSET}
        for pair in args.pairs.split(","):
            for who in ("neepp", "pbrt"):
                q = render_pair(who, scene, pair, args, work, f"{pair}_d{d}", res=res, spp=spp, max_depth=d, seed=1)
                row[f"{who} {pair} Y"] = luminance(channel_means(q["image"]))
            row[f"pbrt/neepp {pair}"] = (row[f"pbrt {pair} Y"] / row[f"neepp {pair} Y"]
                                         if row[f"neepp {pair} Y"] > 0 else float("nan"))
        rows.append(row)
        print(json.dumps(rows[-1]), flush=True)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pbrt", required=True, help="path to pbrt-v4's pbrt executable")
    ap.add_argument("--imgtool", default=None, help="pbrt-v4's imgtool (default: beside --pbrt); converts envmaps")
    ap.add_argument("--pbrt-scenes", required=True, help="folder with <scene>/pbrt/scene-v4.pbrt (gonsolo/bitterli)")
    ap.add_argument("--pbrt-lightsampler", default="bvh", help='pbrt "path" light sampler (bvh, power, uniform)')
    ap.add_argument("--scenes", default="cornell-box,veach-ajar")
    ap.add_argument("--pairs", default="path,bdpt", help=f"comma list of {list(PAIRS)}")
    ap.add_argument("--spp", type=int, default=0, help="spp; 0: per-scene default")
    ap.add_argument("--scale", type=int, default=4, help="divide the scene's film size by this")
    ap.add_argument("--max-depth", type=int, default=17, help="Mitsuba max_depth = pbrt maxdepth + 1")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-other-load", type=float, default=0.3,
                    help="rerun a round when others used more than this many cores during a render")
    ap.add_argument("--retries", type=int, default=2)
    ap.add_argument("--wait-quiet", type=float, default=0.0,
                    help="before each render wait up to this many seconds for the machine to go quiet "
                         "(others using under --max-other-load cores)")
    ap.add_argument("--label", default="", help="note on the pbrt build for the report (commit, flags)")
    ap.add_argument("--check-depth", action="store_true", help="only compare means at max_depth 1..4")
    ap.add_argument("--scenes-dir", default=str(SCENES_DIR))
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "pbrt_peer"))
    a = ap.parse_args(argv)
    if runner.find_neepp() is None:
        ap.error("neepp binary not found (build/neepp or NEEPP_BIN)")
    if a.imgtool is None:
        a.imgtool = str(Path(a.pbrt).with_name("imgtool"))
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    if a.check_depth:
        rows = check_depth(a, out)
        print(report.markdown_table(rows))
        return 0
    rows = []
    for scene in a.scenes.split(","):
        for pair in a.pairs.split(","):
            rows.append(measure(scene, pair, a, out))
            (out / "results.json").write_text(json.dumps({"machine": machine.describe(), "pbrt": a.pbrt,
                                                          "label": a.label, "rows": rows}, indent=2))
    cols = ["scene", "pair", "res", "max_depth", "spp", "neepp s", "pbrt s", "neepp samples/s", "pbrt samples/s",
            "ratio (median)", "ratio min", "ratio max", "cpu-time ratio (median)", "neepp Y", "pbrt Y", "ref Y",
            "neepp/ref", "pbrt/ref", "neepp relMSE", "pbrt relMSE", "efficiency ratio", "max other load (cores)"]
    md = [f"# neepp vs pbrt-v4 ({a.threads} threads, box filter, independent sampler, max_depth {a.max_depth} = "
          f"pbrt maxdepth {a.max_depth - DEPTH_OFFSET}, pbrt path light sampler {a.pbrt_lightsampler}, "
          f"{a.rounds} rounds)\n\nmachine: {machine.summary()}\n\npbrt: {a.pbrt} {a.label}\n\n",
          report.markdown_table(rows, cols), "\n\nImage means per channel (R, G, B), all rounds averaged:\n\n",
          report.markdown_table([{"scene": r["scene"], "pair": r["pair"],
                                  "neepp": ", ".join(f"{x:.4f}" for x in r["neepp RGB"]),
                                  "pbrt": ", ".join(f"{x:.4f}" for x in r["pbrt RGB"]),
                                  "reference": ", ".join(f"{x:.4f}" for x in r["ref RGB"])} for r in rows]),
          "\n\nScene edits (gonsolo/bitterli's pbrt-v4 file -> the Mitsuba scene):\n\n",
          "".join(f"- {s}: {'; '.join(n) or 'none'}\n" for s, n in
                  dict((r["scene"], r["scene edits"]) for r in rows).items()),
          "\nRounds (render seconds, neepp/pbrt samples/s ratio, others' CPU use in cores during each render):\n\n",
          report.markdown_table([{"scene": r["scene"], "pair": r["pair"], "round": x["round"], "seed": x["seed"],
                                  "first": x["order"][0], "neepp s": x["neepp_render_time_s"],
                                  "pbrt s": x["pbrt_render_time_s"], "ratio": x["ratio"],
                                  "cpu-time ratio": x["cpu_ratio"],
                                  "neepp other load": x["neepp_other_load_cores"],
                                  "pbrt other load": x["pbrt_other_load_cores"]}
                                 for r in rows for x in r["rounds_detail"]]), "\n"]
    (out / "report.md").write_text("".join(md))
    print("".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
