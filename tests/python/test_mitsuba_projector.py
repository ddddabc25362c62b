"""Mitsuba 3's `projector` light: small scenes of the project's own lit by a projector (a constant
irradiance with `scale` and a 50 mm default focal length; and a 6 x 3 bitmap, uneven and asymmetric, so a
mirrored, flipped or stretched projection shows, with fov_axis y) throwing light on a floor, a box and a
sphere, under a dim constant sky; rendered by neepp's path tracer, BDPT and light tracer, they agree
with Mitsuba 3's images: the mean within 1 % plus 4 standard errors, each of 3 x 3 regions within 2 %
plus 4 standard errors."""
from __future__ import annotations

import pytest

from mitsuba_compare import mitsuba_render, neepp_agrees, sensor, slide
from neepp_tools import REPO_ROOT, exr

OUT = REPO_ROOT / ".cache" / "test_mitsuba_projector"

SCENE = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.3"/><rotate y="1" angle="20"/><translate x="-0.5" y="0.3" z="0.2"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.5,0.3"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.5" y="0.35" z="-0.2"/><float name="radius" value="0.35"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.3,0.5,0.8"/></bsdf></shape>
  <emitter type="projector"><transform name="to_world"><lookat origin="-0.8,2.2,1.6" target="0.1,0,-0.1" up="0,1,0"/></transform>
    @PROJECTOR@</emitter>
  <emitter type="constant"><rgb name="radiance" value="0.05"/></emitter>
</scene>
"""

PROJECTORS = {
    "constant": '<rgb name="irradiance" value="0.8,0.6,0.4"/><float name="scale" value="4"/>',
    "bitmap": '<texture type="bitmap" name="irradiance"><string name="filename" value="slide.exr"/>'
              '<string name="filter_type" value="nearest"/></texture>'
              '<float name="fov" value="40"/><string name="fov_axis" value="y"/><float name="scale" value="2.5"/>',
}


@pytest.fixture(scope="module", params=list(PROJECTORS))
def scene_and_reference(request, tmp_path_factory):
    d = tmp_path_factory.mktemp("projector")
    exr.write_exr(d / "slide.exr", slide())
    xml = d / f"projector_{request.param}.xml"
    xml.write_text(SCENE.replace("@SENSOR@", sensor(55, "0,1.6,3.0", "0,0.3,0"))
                   .replace("@PROJECTOR@", PROJECTORS[request.param]))
    return xml, mitsuba_render(xml, OUT / f"mitsuba_{request.param}.exr", spp=1024, seed=2)


@pytest.mark.parametrize("integrator", ["path", "bdpt", "light"])
def test_projector_renders_as_mitsuba_does(integrator, scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    neepp_agrees(xml, ref, integrator, 256, neepp_bin, OUT)
