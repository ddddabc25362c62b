"""The uv parameterisation of Mitsuba 3's built-in shapes (`sphere`, `disk`, `cylinder`, `rectangle`, `cube`)
and its partials dp/du and dp/dv, as textures, bump maps and tangent-space normal maps see them: each shape,
turned so that both of its uv directions show, under a bitmap reflectance (where the uv is read), a bump map
over rough plastic (where a bump's slope along u and along v tilts the normal by the lengths and directions
of dp/du and dp/dv) and a normal map over rough plastic (where the map's x and y follow the shading frame's
s and t), rendered by neepp's path tracer, agrees with Mitsuba 3's image: the mean within 1 % plus 4
standard errors, each of 3 x 3 regions within 2 % plus 4 standard errors, and every 12 x 12 block of pixel
differences passing a z-test. A sphere whose dp/dv had the wrong length and sign, or a disk whose dp/dv did
not shrink toward its centre (a mesh's, interpolated over each fan triangle), fails the bump-map case; a bump
map whose perturbed frame's s was the world dp/du (not Mitsuba's, see materials/bumpmap.cpp) fails the case of
a bump map over an anisotropic rough conductor."""
from __future__ import annotations

import numpy as np
import pytest

from mitsuba_compare import assert_agrees, assert_blocks_agree, mitsuba_render, sensor
from neepp_tools import REPO_ROOT, exr, runner

OUT = REPO_ROOT / ".cache" / "test_mitsuba_shape_uv"

# Each shape with a to_world that turns it so the camera sees both of its uv directions (and, for the sphere,
# a pole and the equator; for the cube, three faces).
SHAPES = {
    "sphere": """<shape type="sphere"><transform name="to_world"><rotate x="1" angle="-60"/><rotate y="1" angle="20"/></transform>""",
    "disk": """<shape type="disk"><transform name="to_world"><scale value="1.2"/><rotate x="1" angle="-30"/><rotate y="1" angle="25"/></transform>""",
    "cylinder": """<shape type="cylinder"><point name="p0" x="0" y="-1" z="0"/><point name="p1" x="0.2" y="1" z="0.1"/>
    <float name="radius" value="0.8"/>""",
    "rectangle": """<shape type="rectangle"><transform name="to_world"><scale x="1.3" y="0.9" z="1"/><rotate x="1" angle="-35"/><rotate z="1" angle="15"/></transform>""",
    "cube": """<shape type="cube"><transform name="to_world"><scale value="0.75"/><rotate y="1" angle="30"/><rotate x="1" angle="20"/></transform>""",
}

ROUGH_PLASTIC = """<bsdf type="roughplastic"><float name="alpha" value="0.15"/><rgb name="diffuse_reflectance" value="0.6,0.5,0.4"/></bsdf>"""
# What each case puts on the shape: the uv read directly, through a height's gradient, through a normal map.
MATERIALS = {
    "texture": """<bsdf type="diffuse"><texture name="reflectance" type="bitmap"><string name="filename" value="pattern.exr"/></texture></bsdf>""",
    "bump": f"""<bsdf type="bumpmap">
      <texture name="map" type="bitmap"><string name="filename" value="height.exr"/><boolean name="raw" value="true"/></texture>
      <float name="scale" value="0.08"/>{ROUGH_PLASTIC}</bsdf>""",
    # The bump map over an anisotropic BSDF, which sees the perturbed frame's s as well as its normal.
    "anisotropic_bump": f"""<bsdf type="bumpmap">
      <texture name="map" type="bitmap"><string name="filename" value="height.exr"/><boolean name="raw" value="true"/></texture>
      <float name="scale" value="0.08"/>
      <bsdf type="roughconductor"><float name="alpha_u" value="0.12"/><float name="alpha_v" value="0.5"/></bsdf></bsdf>""",
    "normal": f"""<bsdf type="normalmap">
      <texture name="normalmap" type="bitmap"><string name="filename" value="normals.exr"/><boolean name="raw" value="true"/></texture>
      {ROUGH_PLASTIC}</bsdf>""",
}

# The shape at the origin, seen from the front and above, lit from the upper left by a small area light
# (where a tilted normal moves the highlight) under a dim sky.
SCENE = """<scene version="3.0.0">
  <default name="spp" value="64"/>
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  @SENSOR@
  @SHAPE@
    @MATERIAL@
  </shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><lookat origin="-2,2.5,3" target="0,0,0" up="0,1,0"/></transform>
    <emitter type="area"><rgb name="radiance" value="12"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.08"/></emitter>
</scene>
"""


def grid(size: int):
    """Texel centres (u, v), each (size, size), u along a row."""
    c = (np.arange(size) + 0.5) / size
    return np.meshgrid(c, c)


def pattern(size: int = 64) -> np.ndarray:
    """An RGB texture whose red rises along u and green along v, with a checkerboard of 6 x 4 squares in
    blue: a mirrored, swapped or shifted uv shows in the colour of every region."""
    u, v = grid(size)
    checker = (np.floor(6 * u) + np.floor(4 * v)) % 2
    return np.stack([0.15 + 0.7 * u, 0.15 + 0.7 * v, 0.1 + 0.6 * checker], -1).astype(np.float32)


def height(size: int = 128) -> np.ndarray:
    """Ridges along both u and v, of different counts, sloping one way on average (a saw-like profile), so
    that a bump's slope along each direction, and its sign, shows."""
    u, v = grid(size)
    h = 0.5 + 0.25 * np.sin(2 * np.pi * 5 * u + 0.8 * np.sin(2 * np.pi * 5 * u)) \
        + 0.25 * np.cos(2 * np.pi * 4 * v + 0.8 * np.sin(2 * np.pi * 4 * v))
    return np.repeat(h[..., None], 3, 2).astype(np.float32)


def normals(size: int = 64) -> np.ndarray:
    """Tangent-space normals leaning along x with u and along y with v, both one way on average, encoded as
    (n + 1) / 2."""
    u, v = grid(size)
    nx = 0.3 + 0.5 * np.sin(2 * np.pi * 3 * u)
    ny = 0.35 + 0.45 * np.cos(2 * np.pi * 2 * v)
    n = np.stack([nx, ny, np.ones_like(nx)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return ((n + 1) / 2).astype(np.float32)


@pytest.fixture(scope="module")
def textures(tmp_path_factory):
    folder = tmp_path_factory.mktemp("shape_uv")
    exr.write_exr(folder / "pattern.exr", pattern())
    exr.write_exr(folder / "height.exr", height())
    exr.write_exr(folder / "normals.exr", normals())
    return folder


def scene(shape: str, material: str) -> str:
    return (SCENE.replace("@SENSOR@", sensor(34, "0.3,1.2,4", "0,0,0")).replace("@SHAPE@", SHAPES[shape])
            .replace("@MATERIAL@", MATERIALS[material]))


# Every shape with every material but the anisotropic bump, which goes through the same code on every shape
# (the bump map's frame) and is tried on two, whose dp/du is along world x at no point.
CASES = [(shape, material) for shape in SHAPES for material in MATERIALS if material != "anisotropic_bump"] + \
    [("sphere", "anisotropic_bump"), ("rectangle", "anisotropic_bump")]


@pytest.mark.parametrize("shape,material", CASES)
def test_shape_uv_and_partials_as_in_mitsuba(shape, material, textures, neepp_bin):
    xml = textures / f"{shape}_{material}.xml"
    xml.write_text(scene(shape, material))
    ref = mitsuba_render(xml, OUT / f"mitsuba_{shape}_{material}.exr", spp=512, seed=1)
    r = runner.run_neepp(xml, OUT / f"neepp_{shape}_{material}.exr", spp=512, seed=3, binary=neepp_bin)
    assert (r.image == r.image).all(), "NaN in the image"
    what = (shape, material)
    assert_agrees(r.image, ref, what)
    # A frame turned about the normal moves an anisotropic highlight along thin streaks, which 12-pixel
    # blocks average away (a wrong s fails 1 to 3 of 12 of them, and 3 to 5 of 48 blocks of 6).
    assert_blocks_agree(r.image, ref, what, block=6 if material == "anisotropic_bump" else 12)
