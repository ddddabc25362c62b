"""Mitsuba 3's `disk` and `cylinder` shapes, `spot` (plain and projecting a texture) and `directional` lights, `null` and `roughdielectric`
BSDFs: small scenes
of the project's own (a spot light across a floor, a tilted cylinder between p0 and p1, a disk-shaped area light
and a tilted diffuse disk; a sun-like directional light on a floor, a glossy sphere and a box) rendered by
neepp's path tracer, BDPT and light tracer agree with Mitsuba 3's images: the mean within 1 % plus 4
standard errors, and each of 3 x 3 regions within 2 % plus 4 standard errors (so a disk facing the wrong
way, a cylinder along the wrong axis, a spot's falloff or a light arriving from the wrong side shows)."""
from __future__ import annotations

import pytest

from mitsuba_compare import mitsuba_render, neepp_agrees, sensor, slide
from neepp_tools import REPO_ROOT, exr

OUT = REPO_ROOT / ".cache" / "test_mitsuba_shapes_lights"

SHAPES_AND_SPOT = """<scene version="3.0.0">
  <default name="spp" value="16"/><default name="max_depth" value="5"/>
  <integrator type="path"><integer name="max_depth" value="$max_depth"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="cylinder"><point name="p0" x="-0.6" y="0" z="0"/><point name="p1" x="-0.4" y="1.2" z="-0.3"/>
    <float name="radius" value="0.3"/>
    <bsdf type="roughplastic"><float name="alpha" value="0.2"/><rgb name="diffuse_reflectance" value="0.2,0.4,0.7"/></bsdf></shape>
  <shape type="disk"><transform name="to_world"><scale value="0.4"/><rotate x="1" angle="90"/><translate x="0.6" y="1.8"/></transform>
    <emitter type="area"><rgb name="radiance" value="6"/></emitter></shape>
  <shape type="disk"><transform name="to_world"><scale value="0.5"/><rotate y="1" angle="-30"/><translate x="0.7" y="0.5" z="-0.5"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8,0.6,0.3"/></bsdf></shape>
  <emitter type="spot"><transform name="to_world"><lookat origin="-1.5,2.5,1.5" target="0,0,0" up="0,1,0"/></transform>
    <rgb name="intensity" value="20"/><float name="cutoff_angle" value="25"/></emitter>
</scene>
"""

# A spot light projecting a bitmap over its cone (uneven and asymmetric, so a mirrored or flipped projection
# shows), tilted, onto a floor and a box under a dim sky.
TEXTURED_SPOT = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.3"/><rotate y="1" angle="20"/><translate x="-0.5" y="0.3" z="0.2"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.5,0.3"/></bsdf></shape>
  <emitter type="spot"><transform name="to_world"><lookat origin="-0.6,2.4,1.2" target="0.1,0,-0.1" up="0,1,0"/></transform>
    <rgb name="intensity" value="6"/><float name="cutoff_angle" value="35"/><float name="beam_width" value="25"/>
    <texture type="bitmap" name="texture"><string name="filename" value="slide.exr"/></texture></emitter>
  <emitter type="constant"><rgb name="radiance" value="0.05"/></emitter>
</scene>
"""

DIRECTIONAL = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="5"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="0.6" z="0"/><float name="radius" value="0.5"/>
    <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="-1" y="0.3" z="-0.5"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.3,0.2"/></bsdf></shape>
  <emitter type="directional"><vector name="direction" value="0.5,-1,-0.3"/><rgb name="irradiance" value="2,1.8,1.5"/></emitter>
</scene>
"""

# A `null` sphere between the camera and the scene (no effect on light, but its crossings are bounces, as
# in Mitsuba), and an area light whose shape has a `null` BSDF.
NULL_BSDF = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="-0.5" y="0.3"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.2,0.6,0.3"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.2" y="0.6" z="1"/><float name="radius" value="0.6"/>
    <bsdf type="null"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate x="1" angle="90"/><translate y="2"/></transform>
    <bsdf type="null"/><emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
</scene>
"""

# Rough glass: a GGX sphere (visible normals) and an anisotropic Beckmann cube sampled without visible
# normals, with tinted multipliers, on a floor under an area light and a constant sky (which keeps the
# noise low enough that dropping the cube's tint fails the comparison): the caustics through them reach
# the floor by refraction both ways, what the light tracer and BDPT's light subpaths carry as importance.
ROUGH_DIELECTRIC = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="8"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.45" y="0.55" z="0"/><float name="radius" value="0.5"/>
    <bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="0.15"/>
      <string name="int_ior" value="bk7"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.45"/><rotate y="1" angle="30"/><translate x="-0.65" y="0.45" z="0.2"/></transform>
    <bsdf type="roughdielectric"><string name="distribution" value="beckmann"/><float name="alpha_u" value="0.1"/>
      <float name="alpha_v" value="0.35"/><float name="int_ior" value="1.33"/><boolean name="sample_visible" value="false"/>
      <rgb name="specular_transmittance" value="0.2,0.5,0.9"/><rgb name="specular_reflectance" value="0.8"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.8"/><rotate x="1" angle="90"/><translate x="0.2" y="2.2" z="-0.2"/></transform>
    <emitter type="area"><rgb name="radiance" value="4"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.3"/></emitter>
</scene>
"""

SCENES = {name: xml.replace("@SENSOR@", sensor(60, "0,1.2,3.2", "0,0.6,0"))
          for name, xml in {"shapes_and_spot": SHAPES_AND_SPOT, "textured_spot": TEXTURED_SPOT, "directional": DIRECTIONAL,
                            "null_bsdf": NULL_BSDF, "rough_dielectric": ROUGH_DIELECTRIC}.items()}


@pytest.fixture(scope="module", params=list(SCENES))
def scene_and_reference(request, tmp_path_factory):
    d = tmp_path_factory.mktemp("shapes_lights")
    exr.write_exr(d / "slide.exr", slide())
    xml = d / f"{request.param}.xml"
    xml.write_text(SCENES[request.param])
    return xml, mitsuba_render(xml, OUT / f"mitsuba_{request.param}.exr", spp=1024, seed=2)


@pytest.mark.parametrize("integrator", ["path", "bdpt", "light"])
def test_renders_as_mitsuba_does(integrator, scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    neepp_agrees(xml, ref, integrator, 256, neepp_bin, OUT)
