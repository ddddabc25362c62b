"""Mitsuba 3's `pplastic` (polarized plastic) and `polarizer`, as its RGB variants render them: a pplastic
sphere (Beckmann, Mitsuba's documentation example) on an anisotropic GGX pplastic floor, seen partly through
a tilted polarizer sheet whose transmittance is a checkerboard. neepp's path tracer and BDPT agree with
Mitsuba 3's image: the mean within 1 % plus 4 standard errors, each of 3 x 3 regions within 2 % plus 4
standard errors, every 12 x 12 block of pixel differences passing a z-test.

Without polarization the sheet passes every ray straight through with half its transmittance, and stops
shadow rays (Mitsuba's path tracer treats it as any surface for visibility): the shadow it casts and the
darker view through it both test that."""
from __future__ import annotations

import pytest

from mitsuba_compare import neepp_agrees, scene_and_mitsuba, sensor
from neepp_tools import REPO_ROOT

OUT = REPO_ROOT / ".cache" / "test_mitsuba_pplastic_polarizer"

SCENE = """<scene version="3.0.0">
  <default name="spp" value="64"/>
  <integrator type="path"><integer name="max_depth" value="5"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="1.5"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="pplastic"><string name="distribution" value="ggx"/>
      <float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.3"/>
      <rgb name="diffuse_reflectance" value="0.6,0.5,0.3"/><float name="int_ior" value="1.6"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="0.5" z="0"/><float name="radius" value="0.5"/>
    <bsdf type="pplastic"><rgb name="diffuse_reflectance" value="0.05, 0.03, 0.1"/><float name="alpha" value="0.06"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.6" y="0.5"/><rotate y="1" angle="30"/>
      <translate x="0.5" y="0.6" z="1"/></transform>
    <bsdf type="polarizer"><float name="theta" value="45"/>
      <texture name="transmittance" type="checkerboard"><rgb name="color0" value="0.9,0.7,0.4"/>
        <rgb name="color1" value="0.3"/></texture></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate y="1" angle="-90"/><translate x="2" y="1.2"/></transform>
    <emitter type="area"><rgb name="radiance" value="20"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.3"/></emitter>
</scene>
"""


@pytest.fixture(scope="module")
def scene_and_reference(tmp_path_factory):
    return scene_and_mitsuba(tmp_path_factory.mktemp("pplastic"), "pplastic",
                             SCENE.replace("@SENSOR@", sensor(45, "0.5,2.2,3", "0,0.4,0")), OUT)


@pytest.mark.parametrize("integrator", ["path", "bdpt"])
def test_pplastic_and_polarizer_shade_as_in_mitsuba(integrator, scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    neepp_agrees(xml, ref, integrator, 1024, neepp_bin, OUT, blocks=True)
