#!/usr/bin/env python3
"""neepp against a peer renderer, Benedikt Bitterli's Tungsten: BDPT and PSSMLT speed and image means.

For each scene (default cornell-box and veach-ajar) and integrator pair

    bdpt   : neepp --integrator bdpt    vs Tungsten "bidirectional_path_tracer"
    pssmlt : neepp --integrator pssmlt  vs Tungsten "kelemen_mlt" (Kelemen PSSMLT over BDPT)

both renderers render the same camera at the same resolution (the scene's own film size divided by
--scale), the same maximum path length, the same spp (for PSSMLT: mutations per pixel), box pixel filter and
the same number of threads, taking turns to go first, --rounds times with different seeds. The table gives
each renderer's render time (scene loading and acceleration-structure build excluded: neepp's stats
`render_time_s`, Tungsten's "Finished render. Render time ..." line), samples/s = pixels*spp / render time,
the neepp/Tungsten ratio of each round's pair (median; metrics.paired_ratios; also the ratio of samples per
CPU second of the render, which others' load on the machine disturbs less), and the image means (R, G, B,
Rec. 709 luminance) of both renderers (all rounds averaged) and of the Mitsuba 3 reference in
../shared/scenes/<scene>/reference/. For context it also gives each renderer's relMSE against the reference
(box-downsampled to the render's resolution; median over rounds) and the efficiency ratio
(relMSE x time of Tungsten over neepp's: how much less time neepp needs for the same error at this spp).

Path length. neepp takes Mitsuba 3's max_depth: the number of path segments (edges), max_depth=2 is direct
lighting. Tungsten's max_bounces counts the same thing: its path tracer and BDPT trace camera/light
subpaths of at most max_bounces+1 vertices (camera or light point included) and connect s+t <= max_bounces+1
vertices, i.e. at most max_bounces segments; max_bounces=2 is direct lighting. So max_bounces = max_depth
(--check-depth renders max_depth 1..4 with both to show it: the means agree to 0.1-0.2 %, and
max_depth 1 is the light alone). Tungsten's own json2xml writes Mitsuba
maxDepth = max_bounces + 1, which is one segment too many.

Load. The machine may be shared. Around each render the script reads /proc/stat and the children's rusage:
"other load" is the CPU time used by anything but the render, in cores, during the render's process
lifetime. A round whose render saw more than --max-other-load cores is run again (up to --retries times,
the least disturbed attempt is kept, the table's "max other load" says how disturbed);
--wait-quiet S waits up to S seconds before each render for the machine to go quiet.

Tungsten's scenes. With --tungsten-scenes DIR, DIR/<scene>/tungsten/scene.json (the layout of the
gonsolo/bitterli repository, Bitterli's own Tungsten versions of his scenes) is used when it exists: the
script edits a copy (resolution, filter, integrator, spp, outputs, adaptive sampling off). A scene without one
there (veach-ajar: gonsolo/bitterli holds only its pbrt version) is converted at run time from the Mitsuba
scene.xml that neepp renders (meshes, textures, cameras, BSDFs and the area light; PLY meshes are written
as OBJ copies in the output folder). --convert converts every scene, which checks the converter against
Bitterli's own JSON on cornell-box. Nothing of Tungsten or of the scenes is kept in this repository.

Settings made equal: Tungsten's adaptive sampling is off (Bitterli's files turn it on) and its sampler is
"stratified_sampler": false, i.e. independent numbers as the scenes' independent sampler; both PSSMLTs run over
BDPT with large-step probability --mlt-large-step and --mlt-bootstrap bootstrap samples (neepp's defaults;
Tungsten's are 0.1 and 10000). Not equal: Tungsten's kelemen_mlt runs one chain per thread, neepp 1024; each
renderer keeps its own Russian roulette, MIS and small-step mutation.

Building Tungsten (only for this measurement; never commit it or its scenes):

    # the public repositories tunabrain/tungsten (tested at 88ea020; src/, cmake/ and data/ are needed: CMake
    # copies data/) and gonsolo/bitterli, as plain clones, e.g. in /work/peers/tungsten and /work/peers/bitterli
    cd /work/peers/tungsten && mkdir build && cd build
    cmake -DCMAKE_BUILD_TYPE=Release -DTARGET_ARCHITECTURE=zen ..     # its CPU autodetection knows no
    make -j2 tungsten                                               # Zen 4/5 or "AMD EPYC": name one
    # = Tungsten's own defaults: -O3, SSE4.2 (its CMakeLists disables AVX), Embree 2 with SSE4.2 kernels.
    # It builds unchanged with GCC 12 (Debian 12). OpenEXR 3 is not found (it looks for OpenEXR 2's IlmImf),
    # so its HDR output goes to .pfm, which this script reads. Qt5 is absent, so no editor is built.
    # A build with the host's vector units, for comparison (-march=native alone enables AVX-512, which Embree
    # 2's old AVX-512 code does not compile with):
    #   cmake -DCMAKE_BUILD_TYPE=Release -DTARGET_ARCHITECTURE=none -DUSE_SSE4_2=ON -DEMBREE_MAX_ISA=AVX2 \
    #         -DCMAKE_CXX_FLAGS="-march=native -mno-avx512f" -DCMAKE_C_FLAGS="-march=native -mno-avx512f" ..

    .venv/bin/python bench/tungsten_peer.py --tungsten /work/peers/tungsten/build/tungsten \\
        --tungsten-scenes /work/peers/bitterli --wait-quiet 900
    .venv/bin/python bench/tungsten_peer.py ... --scenes cornell-box --pairs bdpt --rounds 1 --spp 4
    .venv/bin/python bench/tungsten_peer.py ... --check-depth                  # max_depth mapping check

Writes bench/out/tungsten_peer/ (git-ignored): report.md, results.json, the generated Tungsten scenes, the
images (EXR) and per scene/pair a side-by-side PNG (neepp | Tungsten | reference).
"""
from __future__ import annotations

import argparse
import json
import math
import re
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import SCENES_DIR, credit, exr, machine, report, runner  # noqa: E402
from peer_rounds import channel_means, luminance, run_rounds, summarize_rounds  # noqa: E402

#: name: (neepp integrator, Tungsten integrator type)
PAIRS = {"bdpt": ("bdpt", "bidirectional_path_tracer"), "pssmlt": ("pssmlt", "kelemen_mlt")}
#: spp (mutations per pixel for pssmlt) per scene and pair, about 10-30 s a render with 2 threads at scale 4
DEFAULT_SPP = {("cornell-box", "bdpt"): 64, ("veach-ajar", "bdpt"): 32,
               ("cornell-box", "pssmlt"): 64, ("veach-ajar", "pssmlt"): 24}


# ----------------------------------------------------------------------------------------------
# Mitsuba 3 XML (the subset the evaluation scenes use) -> Tungsten JSON


def _floats(s: str) -> list[float]:
    return [float(x) for x in re.split(r"[,\s]+", s.strip()) if x]


def _substitute(root: ET.Element, defines: dict) -> None:
    values = {d.get("name"): d.get("value") for d in root.iter("default")}
    values.update({k: str(v) for k, v in defines.items()})
    for el in root.iter():
        for k, v in el.attrib.items():
            if "$" in v:
                el.set(k, re.sub(r"\$(\w+)", lambda m: values[m.group(1)], v))


def _matrix(el: ET.Element | None) -> np.ndarray:
    """A <transform> (matrix, scale, translate, lookat, in order) as a 4x4 array."""
    m = np.eye(4)
    if el is None:
        return m
    for op in el:
        if op.tag == "matrix":
            t = np.array(_floats(op.get("value"))).reshape(4, 4)
        elif op.tag == "scale":
            s = [float(op.get(k, op.get("value", 1))) for k in "xyz"]
            t = np.diag(s + [1.0])
        elif op.tag == "translate":
            t = np.eye(4)
            t[:3, 3] = [float(op.get(k, 0)) for k in "xyz"]
        elif op.tag == "lookat":
            o, tgt, up = (np.array(_floats(op.get(k))) for k in ("origin", "target", "up"))
            d = (tgt - o) / np.linalg.norm(tgt - o)
            left = np.cross(up / np.linalg.norm(up), d)
            left /= np.linalg.norm(left)
            t = np.eye(4)
            t[:3, 0], t[:3, 1], t[:3, 2], t[:3, 3] = left, np.cross(d, left), d, o
        else:
            raise ValueError(f"transform op <{op.tag}> not supported by the converter")
        m = t @ m
    return m


def _props(el: ET.Element) -> dict:
    p = {}
    for c in el:
        n = c.get("name")
        if c.tag in ("float", "integer"):
            p[n] = float(c.get("value"))
        elif c.tag in ("string", "boolean"):
            p[n] = c.get("value")
        elif c.tag == "rgb":
            v = _floats(c.get("value"))
            p[n] = v * 3 if len(v) == 1 else v
        elif c.tag == "texture":
            p[n] = c
        elif c.tag == "transform":
            p[n] = _matrix(c)
    return p


def _texture(v, scene_dir: Path):
    """Mitsuba texture/colour -> Tungsten texture JSON."""
    if not isinstance(v, ET.Element):
        return v
    p = _props(v)
    kind = v.get("type")
    if kind == "bitmap":
        if "to_uv" in p:
            raise ValueError("bitmap with to_uv not supported by the converter")
        return {"type": "bitmap", "file": str((scene_dir / p["filename"]).resolve()),
                "interpolate": p.get("filter_type", "bilinear") != "nearest",
                "gamma_correct": p.get("raw", "false") != "true"}
    if kind == "checkerboard":
        # Mitsuba: color0 where (frac(s*uv) > 0.5) agrees in u and v, on an OBJ's uv with v flipped (1 - v).
        # Tungsten: on_color where floor(res*uv) differ in parity, on the file's uv. With res = 2s (even) the
        # flip turns parity in v over, so on_color = color0 selects the same squares.
        to_uv = p.get("to_uv", np.eye(4))
        su, sv = to_uv[0, 0], to_uv[1, 1]
        if abs(2 * su - round(2 * su)) > 1e-6 or abs(2 * sv - round(2 * sv)) > 1e-6 or to_uv[0, 3] or to_uv[1, 3]:
            raise ValueError("checkerboard: only to_uv scales with integer 2*scale are converted")
        return {"type": "checker", "on_color": p.get("color0", [0.4] * 3), "off_color": p.get("color1", [0.2] * 3),
                "res_u": int(round(2 * su)), "res_v": int(round(2 * sv))}
    raise ValueError(f"texture type {kind} not supported by the converter")


def _bsdf(el: ET.Element, name: str, scene_dir: Path, emissive: bool = False) -> dict:
    kind = el.get("type")
    if kind == "twosided":  # Tungsten shades every surface two-sided (enable_two_sided_shading)
        return _bsdf(el.find("bsdf"), name, scene_dir, emissive)
    p = _props(el)
    if kind == "diffuse":
        albedo = _texture(p.get("reflectance", [0.5] * 3), scene_dir)
        if emissive and albedo == [0.0, 0.0, 0.0]:
            return {"name": name, "type": "null"}  # Bitterli's Tungsten idiom for an area light's surface
        return {"name": name, "type": "lambert", "albedo": albedo}
    if kind == "roughconductor":
        if "eta" not in p or "k" not in p:
            raise ValueError("roughconductor without explicit eta and k not supported by the converter")
        return {"name": name, "type": "rough_conductor", "distribution": p.get("distribution", "beckmann"),
                "roughness": p.get("alpha", 0.1), "eta": p["eta"], "k": p["k"],
                "albedo": _texture(p.get("specular_reflectance", [1.0] * 3), scene_dir)}
    if kind == "dielectric":
        return {"name": name, "type": "dielectric", "ior": p.get("int_ior", 1.5046) / p.get("ext_ior", 1.000277)}
    raise ValueError(f"bsdf type {kind} not supported by the converter")


def _ply_to_obj(ply: Path, obj: Path) -> None:
    """Binary little-endian PLY (float vertex properties, one face list) -> OBJ with v, vt, vn.

    vt is written as (u, 1 - v): Mitsuba takes a PLY's uv as it is and an OBJ's with v flipped, so the OBJ
    copy reads the same in both conventions."""
    data = ply.read_bytes()
    end = data.index(b"end_header") + len(b"end_header")
    end += 2 if data[end:end + 2] == b"\r\n" else 1
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        raise ValueError(f"{ply}: only binary little-endian PLY is converted")
    types = {"float": "<f4", "float32": "<f4", "double": "<f8", "uchar": "u1", "uint8": "u1", "int": "<i4",
             "int32": "<i4", "uint": "<u4", "uint32": "<u4"}
    elements, cur = [], None
    for line in header:
        w = line.split()
        if w and w[0] == "element":
            cur = [w[1], int(w[2]), []]
            elements.append(cur)
        elif w and w[0] == "property":
            cur[2].append(w[1:])
    off = end
    verts = faces = None
    for name, count, props in elements:
        if name == "vertex":
            dt = np.dtype([(p[1], types[p[0]]) for p in props])
            verts = np.frombuffer(data, dt, count, off)
            off += dt.itemsize * count
        elif name == "face":
            (_, ct, it, _), = props
            n = np.frombuffer(data, types[ct], 1, off)[0]
            dt = np.dtype([("n", types[ct]), ("i", types[it], (int(n),))])
            faces = np.frombuffer(data, dt, count, off)
            if not np.all(faces["n"] == n):
                raise ValueError(f"{ply}: mixed face sizes")
            off += dt.itemsize * count
    idx = faces["i"].astype(np.int64)
    tris = np.concatenate([idx[:, [0, k, k + 1]] for k in range(1, idx.shape[1] - 1)]) + 1
    names = verts.dtype.names
    with open(obj, "w") as f:
        np.savetxt(f, np.stack([verts[c] for c in "xyz"], 1), fmt="v %.7g %.7g %.7g")
        has_uv, has_n = "u" in names and "v" in names, "nx" in names
        if has_uv:
            np.savetxt(f, np.stack([verts["u"], 1.0 - verts["v"]], 1), fmt="vt %.7g %.7g")
        if has_n:
            np.savetxt(f, np.stack([verts[c] for c in ("nx", "ny", "nz")], 1), fmt="vn %.7g %.7g %.7g")
        if has_uv and has_n:
            np.savetxt(f, np.repeat(tris, 3, axis=1), fmt="f %d/%d/%d %d/%d/%d %d/%d/%d")
        elif has_n:
            np.savetxt(f, np.repeat(tris, 2, axis=1), fmt="f %d//%d %d//%d %d//%d")
        elif has_uv:
            np.savetxt(f, np.repeat(tris, 2, axis=1), fmt="f %d/%d %d/%d %d/%d")
        else:
            np.savetxt(f, tris, fmt="f %d %d %d")


def _cube_obj(obj: Path) -> None:
    """Mitsuba's cube, [-1, 1]^3, as 12 outward-facing triangles."""
    v = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    with open(obj, "w") as f:
        f.writelines(f"v {x} {y} {z}\n" for x, y, z in v)
        for a, b, c, d in quads:
            f.write(f"f {a + 1} {b + 1} {c + 1}\nf {a + 1} {c + 1} {d + 1}\n")


def _quad_transform(m: np.ndarray) -> list[float]:
    """Mitsuba rectangle ([-1, 1]^2 in z = 0, front side +z) -> Tungsten quad transform (unit square in
    y = 0, edges = the x and z columns, front side = z x x)."""
    a, b, o = 2 * m[:3, 0], 2 * m[:3, 1], m[:3, 3]
    n_front = np.linalg.inv(m[:3, :3]).T @ np.array([0.0, 0.0, 1.0])  # Mitsuba's normal transform
    e0, e1 = (b, a) if np.dot(np.cross(a, b), n_front) > 0 else (a, b)  # Tungsten's normal is e1 x e0
    n = np.cross(e1, e0)
    t = np.eye(4)
    t[:3, 0], t[:3, 1], t[:3, 2], t[:3, 3] = e0, n / np.linalg.norm(n), e1, o
    return [float(x) for x in t.reshape(-1)]


def mitsuba_to_tungsten(xml: Path, work: Path, defines: dict | None = None) -> dict:
    """Tungsten scene (dict) from a Mitsuba 3 scene.xml: camera, BSDFs, shapes, area lights. Integrator and
    renderer blocks are left to configure_tungsten()."""
    root = ET.parse(xml).getroot()
    _substitute(root, defines or {})
    scene_dir = xml.parent
    work.mkdir(parents=True, exist_ok=True)
    named = {b.get("id"): b for b in root.findall("bsdf")}
    bsdfs, primitives, used = [], [], {}

    def bsdf_name(el: ET.Element, emissive: bool) -> str:
        key = (id(el), emissive)
        if key not in used:
            name = (el.get("id") or f"bsdf{len(used)}") + ("_emitter" if emissive else "")
            used[key] = name
            bsdfs.append(_bsdf(el, name, scene_dir, emissive))
        return used[key]

    for k, sh in enumerate(root.findall("shape")):
        kind, p = sh.get("type"), _props(sh)
        m = _matrix(sh.find("transform"))
        emitter = sh.find("emitter")
        ref = sh.find("ref")
        b_el = named[ref.get("id")] if ref is not None else sh.find("bsdf")
        if b_el is None:
            b_el = ET.fromstring('<bsdf type="diffuse"/>')
        prim = {"name": sh.get("id") or f"shape{k}", "bsdf": bsdf_name(b_el, emitter is not None)}
        if kind == "rectangle":
            prim.update(type="quad", transform=_quad_transform(m))
        elif kind in ("obj", "ply", "cube"):
            if kind == "obj":
                mesh = (scene_dir / p["filename"]).resolve()
            elif kind == "ply":
                mesh = work / (Path(p["filename"]).stem + ".ply.obj")
                if not mesh.exists():
                    _ply_to_obj(scene_dir / p["filename"], mesh)
            else:
                mesh = work / "cube.obj"
                _cube_obj(mesh)
            smooth = kind != "cube" and p.get("face_normals", "false") != "true"
            prim.update(type="mesh", file=str(mesh), smooth=smooth, backface_culling=False,
                        recompute_normals=False, transform=[float(x) for x in m.reshape(-1)])
        else:
            raise ValueError(f"shape type {kind} not supported by the converter")
        if emitter is not None:
            ep = _props(emitter)
            if emitter.get("type") != "area":
                raise ValueError("only area emitters are converted")
            prim["emission"] = ep["radiance"]
        primitives.append(prim)
    if root.findall("emitter"):
        raise ValueError("scene-level emitters (envmaps, ...) are not converted")

    sensor = root.find("sensor")
    sp = _props(sensor)
    film = _props(sensor.find("film"))
    w, h = int(film["width"]), int(film["height"])
    fov = sp["fov"]
    axis = sp.get("fov_axis", "x")
    if axis == "diagonal":
        raise ValueError("fov_axis diagonal not supported by the converter")
    if axis == "y" or (axis == "smaller" and h < w) or (axis == "larger" and h > w):  # Tungsten's is horizontal
        fov = math.degrees(2 * math.atan(math.tan(math.radians(fov) / 2) * w / h))
    cam_m = _matrix(sensor.find("transform"))
    # Tungsten's camera flips the transform's x axis itself; its json2xml writes Mitsuba's to_world as the
    # same matrix, so the matrix goes over unchanged.
    camera = {"type": "pinhole", "fov": fov, "resolution": [w, h], "tonemap": "linear",
              "reconstruction_filter": "box", "transform": [float(x) for x in cam_m.reshape(-1)]}
    return {"media": [], "bsdfs": bsdfs, "primitives": primitives, "camera": camera}


def configure_tungsten(doc: dict, *, res: tuple[int, int], integrator: str, max_depth: int, spp: int,
                       out_pfm: Path, out_png: Path, mlt_large_step: float, mlt_bootstrap: int) -> dict:
    """Set resolution, box filter, integrator, spp and outputs of a Tungsten scene (in place)."""
    cam = doc["camera"]
    cam["resolution"] = [int(res[0]), int(res[1])]
    cam["reconstruction_filter"] = "box"
    integ = {"type": integrator, "min_bounces": 0, "max_bounces": int(max_depth),
             "enable_consistency_checks": False, "enable_two_sided_shading": True}
    if integrator == "kelemen_mlt":
        integ.update(bidirectional=True, large_step_probability=mlt_large_step, initial_sample_pool=mlt_bootstrap,
                     enable_light_sampling=True, enable_volume_light_sampling=True)
    doc["integrator"] = integ
    doc["renderer"] = {"output_file": str(out_png), "hdr_output_file": str(out_pfm),
                       "overwrite_output_files": True, "adaptive_sampling": False, "enable_resume_render": False,
                       "stratified_sampler": False, "scene_bvh": True, "spp": int(spp), "spp_step": 16,
                       "checkpoint_interval": "0", "timeout": "0"}
    return doc


# ----------------------------------------------------------------------------------------------
# running Tungsten


def read_pfm(path: Path) -> np.ndarray:
    """PFM (colour) -> float32 (H, W, 3), top row first."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = (int(x) for x in f.readline().split())
        scale = float(f.readline())
        img = np.fromfile(f, "<f4" if scale < 0 else ">f4", w * h * 3)
    if kind != b"PF":
        raise ValueError(f"{path}: not a colour PFM")
    return np.ascontiguousarray(img.reshape(h, w, 3)[::-1], dtype=np.float32)


def parse_duration(s: str) -> float:
    """Tungsten's StringUtils::durationToString: '1h 2m 3s 456ms', or '0.123s' under a second."""
    s = s.strip()
    m = re.fullmatch(r"(?:(\d+)d )?(?:(\d+)h )?(?:(\d+)m )?(\d+)s (\d+)ms", s)
    if m:
        d, h, mi, sec, ms = (int(x or 0) for x in m.groups())
        return ((d * 24 + h) * 60 + mi) * 60 + sec + ms / 1000.0
    m = re.fullmatch(r"([0-9.eE+-]+)s", s)
    if m:
        return float(m.group(1))
    raise ValueError(f"cannot parse Tungsten duration {s!r}")


def run_tungsten(binary: Path, scene_json: Path, out_pfm: Path, *, threads: int, seed: int,
                 timeout: float = 7200) -> dict:
    for p in (out_pfm,):
        if p.exists():
            p.unlink()
    cmd = [str(binary), "-t", str(threads), "-s", str(seed), str(scene_json)]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=scene_json.parent)
    wall = time.perf_counter() - t0
    log = r.stdout + r.stderr
    m = re.search(r"Finished render\. Render time (.+)", log)
    if r.returncode != 0 or not m or not out_pfm.exists():
        raise runner.RenderError(f"tungsten failed (rc={r.returncode}): {' '.join(cmd)}\n{log[-4000:]}")
    return {"image": read_pfm(out_pfm), "render_time_s": parse_duration(m.group(1)), "wall_s": wall, "log": log}


# ----------------------------------------------------------------------------------------------


def scene_film(xml: Path) -> tuple[int, int]:
    d = {e.get("name"): e.get("value") for e in ET.parse(xml).getroot().iter("default")}
    return int(d["resx"]), int(d["resy"])


def tungsten_base(scene: str, args, work: Path) -> tuple[dict, str]:
    """Bitterli's Tungsten scene for `scene` (a copy), or one converted from the Mitsuba scene.xml."""
    if args.tungsten_scenes and not args.convert:
        for cand in (Path(args.tungsten_scenes) / scene / "tungsten" / "scene.json",
                     Path(args.tungsten_scenes) / scene / "scene.json"):
            if cand.exists():
                return json.loads(cand.read_text()), f"Bitterli's Tungsten scene ({cand})"
    xml = Path(args.scenes_dir) / scene / "scene.xml"
    return mitsuba_to_tungsten(xml, work / "converted"), f"converted at run time from {xml}"


def measure(scene: str, pair: str, args, out: Path) -> dict:
    neepp_integrator, tungsten_integrator = PAIRS[pair]
    xml = Path(args.scenes_dir) / scene / "scene.xml"
    W, H = scene_film(xml)
    w, h = W // args.scale, H // args.scale
    spp = args.spp or DEFAULT_SPP.get((scene, pair), 16)
    work = out / scene / pair
    work.mkdir(parents=True, exist_ok=True)
    base, source = tungsten_base(scene, args, out / scene)
    neepp_opts = {}
    if pair == "pssmlt":
        neepp_opts = {"large_step": args.mlt_large_step, "bootstrap": args.mlt_bootstrap}

    def render(who: str, r: int, seed: int) -> dict:
        if who == "neepp":
            res = runner.run_neepp(xml, work / f"neepp_r{r}.exr", spp=spp, resx=w, resy=h, max_depth=args.max_depth,
                                   seed=seed, threads=args.threads, integrator=neepp_integrator,
                                   integrator_args=neepp_opts, extra_args=["--rfilter", "box"], timeout=7200)
            return {"image": res.image, "render_time_s": float(res.stats["render_time_s"]), "wall_s": res.wall_s,
                    "load_s": res.stats.get("load_time_s")}
        pfm = work / f"tungsten_r{r}.pfm"
        doc = configure_tungsten(json.loads(json.dumps(base)), res=(w, h), integrator=tungsten_integrator,
                                 max_depth=args.max_depth, spp=spp, out_pfm=pfm, out_png=work / f"tungsten_r{r}.png",
                                 mlt_large_step=args.mlt_large_step, mlt_bootstrap=args.mlt_bootstrap)
        sj = work / "tungsten_scene.json"
        sj.write_text(json.dumps(doc, indent=1))
        tr = run_tungsten(Path(args.tungsten), sj, pfm, threads=args.threads, seed=seed)
        exr.write_exr(work / f"tungsten_r{r}.exr", tr["image"])
        return {"image": tr["image"], "render_time_s": tr["render_time_s"], "wall_s": tr["wall_s"]}

    rounds, attempts = run_rounds(args, scene, pair, "tungsten", w * h, spp, render)
    summary, img_n, img_t, ref_small = summarize_rounds(args, scene, "tungsten", rounds, w, h)
    row = {"scene": scene, "pair": pair, "res": f"{w}x{h}", "max_depth": args.max_depth,
           "tungsten max_bounces": args.max_depth, "spp": spp, "rounds": len(rounds), **summary,
           "tungsten scene": source, "attempts": attempts}
    exr.write_exr(work / "neepp_mean.exr", img_n)
    exr.write_exr(work / "tungsten_mean.exr", img_t)
    report.comparison_figure(work / "compare.png", {"neepp": img_n, "tungsten": img_t}, ref=ref_small,
                             title=f"{scene} {pair}: {w}x{h}, {spp} spp x {len(rounds)}, max_depth {args.max_depth}",
                             credit=credit(scene))
    return row


def check_depth(args, out: Path) -> list[dict]:
    """Image means at max_depth 1..4 (neepp) against Tungsten max_bounces 1..4 (BDPT, the first scene)."""
    scene = args.scenes.split(",")[0]
    xml = Path(args.scenes_dir) / scene / "scene.xml"
    W, H = scene_film(xml)
    w, h = W // (2 * args.scale), H // (2 * args.scale)
    base, _ = tungsten_base(scene, args, out / scene)
    rows = []
    for d in (1, 2, 3, 4):
        work = out / scene / "depth"
        work.mkdir(parents=True, exist_ok=True)
        n = runner.run_neepp(xml, work / f"neepp_d{d}.exr", spp=64, resx=w, resy=h, max_depth=d, seed=1,
                             threads=args.threads, integrator="bdpt", extra_args=["--rfilter", "box"])
        doc = configure_tungsten(json.loads(json.dumps(base)), res=(w, h), integrator="bidirectional_path_tracer",
                                 max_depth=d, spp=64, out_pfm=work / f"tungsten_b{d}.pfm",
                                 out_png=work / f"tungsten_b{d}.png", mlt_large_step=args.mlt_large_step,
                                 mlt_bootstrap=args.mlt_bootstrap)
        sj = work / f"tungsten_b{d}.json"
        sj.write_text(json.dumps(doc, indent=1))
        t = run_tungsten(Path(args.tungsten), sj, work / f"tungsten_b{d}.pfm", threads=args.threads, seed=1)
        rows.append({"neepp max_depth / tungsten max_bounces": d, "neepp Y": luminance(channel_means(n.image)),
                     "tungsten Y": luminance(channel_means(t["image"]))})
        print(json.dumps(rows[-1]), flush=True)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tungsten", required=True, help="path to the tungsten command-line renderer")
    ap.add_argument("--tungsten-scenes", default=None,
                    help="folder with <scene>/tungsten/scene.json (gonsolo/bitterli layout); scenes not there "
                         "are converted from the Mitsuba scene.xml")
    ap.add_argument("--scenes", default="cornell-box,veach-ajar")
    ap.add_argument("--pairs", default="bdpt,pssmlt", help=f"comma list of {list(PAIRS)}")
    ap.add_argument("--spp", type=int, default=0, help="spp (pssmlt: mutations per pixel); 0: per-scene default")
    ap.add_argument("--scale", type=int, default=4, help="divide the scene's film size by this")
    ap.add_argument("--max-depth", type=int, default=17, help="Mitsuba max_depth = Tungsten max_bounces")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-other-load", type=float, default=0.3,
                    help="rerun a round when others used more than this many cores during a render")
    ap.add_argument("--retries", type=int, default=2)
    ap.add_argument("--wait-quiet", type=float, default=0.0,
                    help="before each render wait up to this many seconds for the machine to go quiet "
                         "(others using under --max-other-load cores)")
    ap.add_argument("--mlt-large-step", type=float, default=0.3,
                    help="large-step probability for both PSSMLTs (neepp's default)")
    ap.add_argument("--mlt-bootstrap", type=int, default=100000,
                    help="bootstrap samples (Tungsten: initial_sample_pool) for both PSSMLTs (neepp's default)")
    ap.add_argument("--label", default="", help="note on the Tungsten build for the report (commit, flags)")
    ap.add_argument("--convert", action="store_true", help="convert every scene from its Mitsuba scene.xml")
    ap.add_argument("--check-depth", action="store_true", help="only compare means at max_depth 1..4")
    ap.add_argument("--scenes-dir", default=str(SCENES_DIR))
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "tungsten_peer"))
    a = ap.parse_args(argv)
    if runner.find_neepp() is None:
        ap.error("neepp binary not found (build/neepp or NEEPP_BIN)")
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
            (out / "results.json").write_text(json.dumps({"machine": machine.describe(), "rows": rows}, indent=2))
    cols = ["scene", "pair", "res", "max_depth", "spp", "neepp s", "tungsten s", "neepp samples/s",
            "tungsten samples/s", "ratio (median)", "ratio min", "ratio max", "cpu-time ratio (median)", "neepp Y", "tungsten Y", "ref Y",
            "neepp/ref", "tungsten/ref", "neepp relMSE", "tungsten relMSE", "efficiency ratio",
            "max other load (cores)"]
    md = [f"# neepp vs Tungsten ({a.threads} threads, box filter, max_depth {a.max_depth} = Tungsten max_bounces "
          f"{a.max_depth}, {a.rounds} rounds)\n\nmachine: {machine.summary()}\n\n"
          f"tungsten: {a.tungsten} {a.label}\n\n",
          report.markdown_table(rows, cols), "\n\nImage means per channel (R, G, B), all rounds averaged:\n\n",
          report.markdown_table([{"scene": r["scene"], "pair": r["pair"],
                                  "neepp": ", ".join(f"{x:.4f}" for x in r["neepp RGB"]),
                                  "tungsten": ", ".join(f"{x:.4f}" for x in r["tungsten RGB"]),
                                  "reference": ", ".join(f"{x:.4f}" for x in r["ref RGB"]),
                                  "tungsten scene": r["tungsten scene"]} for r in rows]),
          "\n\nRounds (render seconds, neepp/Tungsten samples/s ratio, others' CPU use in cores during each "
          "render):\n\n",
          report.markdown_table([{"scene": r["scene"], "pair": r["pair"], "round": x["round"], "seed": x["seed"],
                                  "first": x["order"][0], "neepp s": x["neepp_render_time_s"],
                                  "tungsten s": x["tungsten_render_time_s"], "ratio": x["ratio"],
                                  "cpu-time ratio": x["cpu_ratio"],
                                  "neepp other load": x["neepp_other_load_cores"],
                                  "tungsten other load": x["tungsten_other_load_cores"]}
                                 for r in rows for x in r["rounds_detail"]]), "\n"]
    (out / "report.md").write_text("".join(md))
    print("".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
