"""Mitsuba 3's `blendbsdf`: a plane blending a diffuse and a rough conductor by a checkerboard texture
(weights 0.15 and 0.85), and a sphere blending a rough plastic and a rough conductor by the float 0.3,
rendered by neepp's path tracer and BDPT agrees with Mitsuba 3's: the mean within 1 % plus 4 standard
errors, each of 3 x 3 regions within 2 % plus 4 standard errors, every 12 x 12 block of pixel differences
passing a z-test.

Only smooth lobes are blended here: where one BSDF has a delta lobe, Mitsuba 3.9 weighs the sampled delta
direction with the other BSDF's density as well (a density added to a probability), which loses energy (a
blend of black diffuse and a mirror at weight 0.5 reflects 0.38 at normal incidence instead of 0.5); neepp
scales the delta lobe by its pick alone (tests/materials/bsdf_properties_test.cpp)."""
from __future__ import annotations

import pytest

from mitsuba_compare import neepp_agrees, scene_and_mitsuba, sensor
from neepp_tools import REPO_ROOT

OUT = REPO_ROOT / ".cache" / "test_mitsuba_blendbsdf"

SCENE = """<scene version="3.0.0">
  <default name="spp" value="64"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="1.5"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="blendbsdf">
      <texture name="weight" type="checkerboard"><rgb name="color0" value="0.15"/><rgb name="color1" value="0.85"/>
        <transform name="to_uv"><scale x="3" y="3"/></transform></texture>
      <bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.6,0.4"/></bsdf>
      <bsdf type="roughconductor"><float name="alpha" value="0.2"/><string name="material" value="Au"/></bsdf>
    </bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="0.5" z="0"/><float name="radius" value="0.5"/>
    <bsdf type="blendbsdf"><float name="weight" value="0.3"/>
      <bsdf type="roughplastic"><float name="alpha" value="0.1"/><rgb name="diffuse_reflectance" value="0.2,0.4,0.7"/></bsdf>
      <bsdf type="roughconductor"><float name="alpha" value="0.3"/><string name="distribution" value="beckmann"/></bsdf>
    </bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate y="1" angle="-90"/><translate x="2" y="1"/></transform>
    <emitter type="area"><rgb name="radiance" value="20"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
</scene>
"""


@pytest.fixture(scope="module")
def scene_and_reference(tmp_path_factory):
    return scene_and_mitsuba(tmp_path_factory.mktemp("blendbsdf"), "blend",
                             SCENE.replace("@SENSOR@", sensor(45, "0,2.5,2.5", "0,0.3,0")), OUT)


@pytest.mark.parametrize("integrator", ["path", "bdpt"])
def test_blends_shade_as_in_mitsuba(integrator, scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    neepp_agrees(xml, ref, integrator, 1024, neepp_bin, OUT, blocks=True)
