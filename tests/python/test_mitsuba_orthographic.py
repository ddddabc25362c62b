"""Mitsuba 3's `orthographic` sensor: a small scene of the project's own seen through an orthographic
camera whose to_world scales the view (x 1.6, y 1.2 on the 4:3 film), tilted by a lookat, with a near
clip plane that cuts the front off a sphere (its inside shows) rendered by neepp's path tracer agrees
with Mitsuba 3's image: the mean within 1 % plus 4 standard errors, and each of 3 x 3 regions within 2 %
plus 4 standard errors; so does a crop window of the film. A view extent off by the aspect ratio, a
mirrored axis, a near plane measured from the wrong place or a crop that rescales shows in the regions."""
from __future__ import annotations

import pytest

from mitsuba_compare import mitsuba_render, neepp_agrees
from neepp_tools import REPO_ROOT

OUT = REPO_ROOT / ".cache" / "test_mitsuba_orthographic"

SCENE = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="orthographic">
    <float name="near_clip" value="4.1"/><float name="far_clip" value="100"/>
    <transform name="to_world"><scale x="1.6" y="1.6"/><lookat origin="2,3,3.5" target="0,0.4,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="36"/>@CROP@<rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.5" y="0.5" z="0.6"/><float name="radius" value="0.5"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.2,0.4,0.8"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.35"/><rotate y="1" angle="25"/><translate x="-0.7" y="0.35" z="-0.4"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8,0.4,0.2"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.6"/><rotate x="1" angle="90"/><translate x="-0.3" y="2.4" z="0.3"/></transform>
    <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.3"/></emitter>
</scene>
"""

CROPS = {"whole": "",
         "cropped": '<integer name="crop_offset_x" value="12"/><integer name="crop_offset_y" value="6"/>'
                    '<integer name="crop_width" value="30"/><integer name="crop_height" value="24"/>'}


@pytest.mark.parametrize("crop", list(CROPS))
def test_orthographic_renders_as_mitsuba_does(crop, tmp_path, neepp_bin):
    xml = tmp_path / f"orthographic_{crop}.xml"
    xml.write_text(SCENE.replace("@CROP@", CROPS[crop]))
    ref = mitsuba_render(xml, OUT / f"mitsuba_{crop}.exr", spp=1024, seed=2)
    neepp_agrees(xml, ref, "path", 256, neepp_bin, OUT)
