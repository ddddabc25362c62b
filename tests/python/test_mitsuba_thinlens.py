"""Mitsuba 3's `thinlens` sensor: a small scene of the project's own (a checkered floor, spheres before, at
and behind the focal plane) seen through a wide lens, rendered by neepp's path tracer and by pssmlt over
it (bdpt and light tracing refuse it: tests/loader), agrees with Mitsuba 3's image: the mean within 1 % plus 4 standard errors, each of 3 x 3 regions within
2 %, and (path) every 12 x 12 block's z-test. The scene's sampler stands at the top level and the sensor
<ref>s it, as Mitsuba's documentation scenes do. A lens sample drawn from the wrong disk, a focal plane at
the wrong depth (measured along the ray instead of the view axis) or a ray that does not start on the lens
blurs the wrong objects, which the regions and blocks show."""
from __future__ import annotations

import pytest

from mitsuba_compare import assert_agrees, assert_tiles_within, mitsuba_render, neepp_agrees
from neepp_tools import REPO_ROOT, runner

OUT = REPO_ROOT / ".cache" / "test_mitsuba_thinlens"

SCENE = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sampler type="independent" id="the_sampler"><integer name="sample_count" value="$spp"/></sampler>
  <sensor type="thinlens">
    <float name="fov" value="45"/><string name="fov_axis" value="smaller"/>
    <float name="aperture_radius" value="0.25"/><float name="focus_distance" value="@FOCUS@"/>
    <transform name="to_world"><lookat origin="0,1.2,5" target="0,0.5,0" up="0,1,0"/></transform>
    <ref id="the_sampler"/>
    <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="36"/><rfilter type="box"/></film>
  </sensor>
  <texture type="checkerboard" id="checks"><rgb name="color0" value="0.1"/><rgb name="color1" value="0.7"/>
    <transform name="to_uv"><scale value="8"/></transform></texture>
  <shape type="rectangle"><transform name="to_world"><scale value="4"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><ref name="reflectance" id="checks"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="-1.0" y="0.4" z="2.6"/><float name="radius" value="0.4"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8,0.3,0.2"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.2" y="0.5" z="0"/><float name="radius" value="0.5"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.2,0.4,0.8"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="1.4" y="0.5" z="-2.5"/><float name="radius" value="0.5"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.3,0.8,0.3"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="1"/><rotate x="1" angle="90"/><translate x="-0.5" y="3" z="1"/></transform>
    <emitter type="area"><rgb name="radiance" value="6"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.25"/></emitter>
</scene>
"""

# In focus: the middle sphere (about 5 away along the view axis), then the near one.
FOCUS = {"middle": 5.0, "near": 2.6}


@pytest.mark.parametrize("focus", list(FOCUS))
def test_thinlens_renders_as_mitsuba_does(focus, tmp_path, neepp_bin):
    xml = tmp_path / f"thinlens_{focus}.xml"
    xml.write_text(SCENE.replace("@FOCUS@", str(FOCUS[focus])))
    ref = mitsuba_render(xml, OUT / f"mitsuba_{focus}.exr", spp=1024, seed=2)
    img = neepp_agrees(xml, ref, "path", 256, neepp_bin, OUT, blocks=True)
    assert_tiles_within(img, ref, (focus, "path"))


def test_thinlens_under_pssmlt(tmp_path, neepp_bin):
    xml = tmp_path / "thinlens_pssmlt.xml"
    xml.write_text(SCENE.replace("@FOCUS@", str(FOCUS["near"])))
    ref = mitsuba_render(xml, OUT / "mitsuba_near.exr", spp=1024, seed=2)
    r = runner.run_neepp(xml, OUT / "neepp_pssmlt.exr", spp=256, seed=3, binary=neepp_bin, integrator="pssmlt",
                         integrator_args={"bidirectional": "false"})
    assert_agrees(r.image, ref, ("near", "pssmlt over path"))
