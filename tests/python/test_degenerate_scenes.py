"""Degenerate scenes: every one renders with every integrator without a crash, a hang or a NaN/Inf in the
film (the film counts what it had to drop: invalid_samples must stay 0), or is refused with one clear
error. Each case is a scene a user can write by accident: a light of zero area or zero power, a
perfectly smooth rough BSDF, an interface that does not refract, meshes with nothing to hit, films of
one pixel and of more pixels than memory holds, a camera inside an object."""
from __future__ import annotations

import json
import resource
import subprocess

import numpy as np
import pytest

from neepp_tools.exr import read_exr

CAMERA = """<sensor type='perspective'><float name='fov' value='60'/>
  <transform name='to_world'><lookat origin='{origin}' target='0,0.5,0' up='0,1,0'/></transform>
  <sampler type='independent'><integer name='sample_count' value='8'/></sampler>
  <film type='hdrfilm'><integer name='width' value='{width}'/><integer name='height' value='{height}'/></film>
</sensor>"""
FLOOR = """<shape type='rectangle'><transform name='to_world'><rotate x='1' angle='-90'/><scale value='3'/></transform>
  <bsdf type='diffuse'/></shape>"""
LIGHT = """<shape type='rectangle'><transform name='to_world'><rotate x='1' angle='90'/><scale value='0.5'/>
  <translate y='2.5'/></transform><emitter type='area'><rgb name='radiance' value='10'/></emitter></shape>"""


def sphere(bsdf: str, radius: float = 0.5) -> str:
    return f"<shape type='sphere'><point name='center' x='0' y='0.5' z='0'/><float name='radius' value='{radius}'/>{bsdf}</shape>"


def scene(*parts: str, origin="0,1.2,3", width=24, height=16) -> str:
    return "<scene version='3.0.0'>" + CAMERA.format(origin=origin, width=width, height=height) + "".join(parts) + "</scene>"


DEGENERATE_OBJ = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 4\nf 4 4 4\n"  # collinear, repeated
VERTICES_ONLY_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
EMPTY_PLY = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n")


def mesh(filename: str, emitter: bool = False) -> str:
    kind = filename.rsplit(".", 1)[1]
    e = "<emitter type='area'><rgb name='radiance' value='5'/></emitter>" if emitter else ""
    return f"<shape type='{kind}'><string name='filename' value='{filename}'/>{e}</shape>"


# name -> scene XML; every one must render.
CASES = {
    "zero_area_light": scene(FLOOR, LIGHT, "<shape type='rectangle'><transform name='to_world'><scale x='0' y='0' z='1'/>"
                             "<translate y='1'/></transform><emitter type='area'><rgb name='radiance' value='10'/></emitter></shape>"),
    "zero_radiance_area_light": scene(FLOOR, LIGHT.replace("value='10'", "value='0'")),
    "zero_radiance_constant": scene(FLOOR, sphere("<bsdf type='diffuse'/>"),
                                    "<emitter type='constant'><rgb name='radiance' value='0'/></emitter>"),
    "zero_intensity_point": scene(FLOOR, "<emitter type='point'><point name='position' x='0' y='2' z='0'/>"
                                  "<rgb name='intensity' value='0'/></emitter>"),
    "point_light_on_the_floor": scene(FLOOR, "<emitter type='point'><point name='position' x='0' y='0' z='0'/>"
                                      "<rgb name='intensity' value='5'/></emitter>"),
    "roughconductor_alpha_0": scene(FLOOR, LIGHT, sphere("<bsdf type='roughconductor'><float name='alpha' value='0'/></bsdf>")),
    "roughconductor_anisotropic_0": scene(FLOOR, LIGHT, sphere(
        "<bsdf type='roughconductor'><float name='alpha_u' value='0'/><float name='alpha_v' value='0.3'/></bsdf>")),
    "roughplastic_alpha_0": scene(FLOOR, LIGHT, sphere("<bsdf type='roughplastic'><float name='alpha' value='0'/></bsdf>")),
    # principled at the ends of its ranges: a mirror-smooth full anisotropy, eta 1 through spec_trans (moved
    # to 1.001), specular 0, the glossiest clearcoat on a black base; principledthin of eta 1 (its
    # transmission's roughness then scales to 0.3) and all diffuse transmission.
    "principled_extremes": scene(FLOOR, LIGHT, sphere(
        "<bsdf type='principled'><float name='roughness' value='0'/><float name='anisotropic' value='1'/>"
        "<float name='spec_trans' value='1'/><float name='eta' value='1'/><float name='sheen' value='1'/></bsdf>"),
        "<shape type='cube'><transform name='to_world'><scale value='0.3'/><translate x='1' y='0.3'/></transform>"
        "<bsdf type='principled'><rgb name='base_color' value='0'/><float name='specular' value='0'/>"
        "<float name='metallic' value='1'/><float name='clearcoat' value='1'/><float name='clearcoat_gloss' value='1'/>"
        "<float name='flatness' value='1'/><float name='roughness' value='1'/></bsdf></shape>"),
    "principledthin_extremes": scene(FLOOR, LIGHT, sphere(
        "<bsdf type='principledthin'><float name='roughness' value='0'/><float name='eta' value='1'/>"
        "<float name='spec_trans' value='1'/><float name='anisotropic' value='1'/></bsdf>"),
        "<shape type='cube'><transform name='to_world'><scale value='0.3'/><translate x='1' y='0.3'/></transform>"
        "<bsdf type='principledthin'><float name='diff_trans' value='2'/><float name='flatness' value='1'/></bsdf></shape>"),
    "dielectric_ior_1": scene(FLOOR, LIGHT, sphere(
        "<bsdf type='dielectric'><float name='int_ior' value='1'/><float name='ext_ior' value='1'/></bsdf>")),
    "thindielectric_ior_1": scene(FLOOR, LIGHT, sphere(
        "<bsdf type='thindielectric'><float name='int_ior' value='1'/><float name='ext_ior' value='1'/></bsdf>")),
    "plastic_ior_1": scene(FLOOR, LIGHT, sphere("<bsdf type='plastic'><float name='int_ior' value='1'/></bsdf>")),
    "roughplastic_ior_1": scene(FLOOR, LIGHT, sphere(
        "<bsdf type='roughplastic'><float name='int_ior' value='1'/><float name='alpha' value='0'/></bsdf>")),
    "degenerate_triangles": scene(FLOOR, LIGHT, mesh("degenerate.obj")),
    "degenerate_triangles_emitting": scene(FLOOR, LIGHT, mesh("degenerate.obj", emitter=True)),
    "zero_triangle_obj": scene(FLOOR, LIGHT, mesh("vertices_only.obj")),
    "zero_triangle_ply_emitting": scene(FLOOR, LIGHT, mesh("empty.ply", emitter=True)),
    "one_pixel_film": scene(FLOOR, LIGHT, sphere("<bsdf type='diffuse'/>"), width=1, height=1),
    "camera_inside_a_sphere": scene(FLOOR, LIGHT, sphere("<bsdf type='diffuse'/>", radius=2), origin="0,0.5,0.2"),
    "camera_inside_a_glass_sphere": scene(FLOOR, LIGHT, sphere("<bsdf type='dielectric'/>", radius=2), origin="0,0.5,0.2"),
    "camera_inside_a_light": scene(FLOOR, LIGHT, "<shape type='sphere'><point name='center' x='0' y='0.5' z='0.2'/>"
                                   "<float name='radius' value='1'/><emitter type='area'><rgb name='radiance' value='1'/>"
                                   "</emitter></shape>", origin="0,0.5,0.2"),
}

# Cases whose emitter has no surface to emit from: it is left out, with a warning.
LEFT_OUT = {"zero_area_light", "degenerate_triangles_emitting", "zero_triangle_ply_emitting"}

# name -> (scene XML, what the one clear error says); refused before rendering, exit status 1.
REFUSED = {
    "zero_area_light_alone": (scene(FLOOR, "<shape type='rectangle'><transform name='to_world'><scale x='0' y='0' z='1'/>"
                                    "</transform><emitter type='area'><rgb name='radiance' value='10'/></emitter></shape>"),
                              "no light source"),
    # 32768^2 pixels need about 100 GB of film buffers: refused up front, not left to the OOM killer (the
    # test caps the address space at 16 GB, so that a machine with more memory than that refuses it too).
    "film_32768_squared": (scene(FLOOR, LIGHT, width=32768, height=32768), "memory"),
}

INTEGRATORS = {
    "path": [],
    "path_neepp": ["-I", "shadow_rays=neepp", "-I", "light_sampler=visibility", "-I", "voxels=4"],
    "bdpt": ["--integrator", "bdpt"],
    "bdpt_neepp": ["--integrator", "bdpt", "-I", "light_paths=neepp", "-I", "voxels=4"],
    "light": ["--integrator", "light"],
}


@pytest.fixture(scope="module")
def scene_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("degenerate")
    (d / "degenerate.obj").write_text(DEGENERATE_OBJ)
    (d / "vertices_only.obj").write_text(VERTICES_ONLY_OBJ)
    (d / "empty.ply").write_text(EMPTY_PLY)
    for name, xml in CASES.items():
        (d / f"{name}.xml").write_text(xml)
    for name, (xml, _) in REFUSED.items():
        (d / f"{name}.xml").write_text(xml)
    return d


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("case", CASES)
def test_degenerate_scene_renders_finite(neepp_bin, scene_dir, tmp_path, case, integrator):
    out, stats = tmp_path / "out.exr", tmp_path / "s.json"
    r = subprocess.run([str(neepp_bin), "render", str(scene_dir / f"{case}.xml"), "-o", str(out), "--stats", str(stats),
                        "--quiet", "--threads", "2", *INTEGRATORS[integrator]], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert ("emitter is left out" in r.stderr) == (case in LEFT_OUT), r.stderr
    s = json.loads(stats.read_text())
    assert s["invalid_samples"] == 0, s
    img = read_exr(out)
    assert np.isfinite(img).all() and img.shape[:2] == (s["height"], s["width"])


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("case", REFUSED)
def test_impossible_scene_is_refused_with_a_clear_error(neepp_bin, scene_dir, tmp_path, case, integrator):
    r = subprocess.run([str(neepp_bin), "render", str(scene_dir / f"{case}.xml"), "-o", str(tmp_path / "out.exr"),
                        "--quiet", *INTEGRATORS[integrator]], capture_output=True, text=True, timeout=60,
                       preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_AS, (16 << 30, 16 << 30)))
    assert r.returncode == 1, (r.returncode, r.stderr)  # an error, not a crash or the OOM killer
    assert "error" in r.stderr and REFUSED[case][1] in r.stderr, r.stderr
    assert not (tmp_path / "out.exr").exists()
