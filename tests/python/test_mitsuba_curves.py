"""Mitsuba 3's curve shapes, `linearcurve` and `bsplinecurve`: a small scene of the project's own (a
zigzag of linear segments whose radius changes from point to point, and a B-spline of two curves, one
of them tapered to open ends, stretched unevenly by its to_world, which moves the points but not the
radii; both textured with checkerboards along u around the tube and v along the file's segments, on a
floor under an area light and a dim sky) rendered by neepp's path tracer agrees with Mitsuba 3's image:
the mean within 1 % plus 4 standard errors, each of 3 x 3 regions within 2 % plus 4 standard errors, and
every 4 x 4 block's z-test. Radii scaled by to_world, a u measured from another direction or a v per
curve instead of per file, normals off the tube, or hits from inside it would show in the blocks."""
from __future__ import annotations

import pytest

from mitsuba_compare import assert_blocks_agree, mitsuba_render, neepp_agrees, sensor
from neepp_tools import REPO_ROOT

OUT = REPO_ROOT / ".cache" / "test_mitsuba_curves"

SCENE = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  @SENSOR@
  <shape type="linearcurve"><string name="filename" value="zigzag.txt"/>
    <transform name="to_world"><translate x="-0.1" z="-0.4"/></transform>
    <bsdf type="diffuse"><texture name="reflectance" type="checkerboard">
      <rgb name="color0" value="0.9,0.5,0.1"/><rgb name="color1" value="0.05,0.1,0.4"/>
      <transform name="to_uv"><scale x="2" y="5"/></transform></texture></bsdf>
  </shape>
  <shape type="bsplinecurve"><string name="filename" value="waves.txt"/>
    <transform name="to_world"><scale x="1.3" y="0.8" z="1"/><rotate y="1" angle="15"/><translate z="0.5"/></transform>
    <bsdf type="diffuse"><texture name="reflectance" type="checkerboard">
      <rgb name="color0" value="0.9,0.8,0.2"/><rgb name="color1" value="0.05,0.3,0.1"/>
      <transform name="to_uv"><scale x="2" y="6"/></transform></texture></bsdf>
  </shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.4"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.6"/><rotate x="1" angle="90"/><translate y="2.6" z="0.8"/></transform>
    <emitter type="area"><rgb name="radiance" value="6"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.25"/></emitter>
</scene>
"""

# x y z radius: one linear curve, its radius changing at every point.
ZIGZAG = """-1.3 0.3 0 0.16
-0.7 1.3 0 0.26
-0.1 0.35 0 0.14
0.5 1.25 0 0.24
1.1 0.4 0 0.18
"""

# Two B-spline curves, a blank line between them: the first tapers to nothing at both ends.
WAVES = """-1.2 0.2 0 0
-0.9 0.6 0.2 0.12
-0.5 0.2 -0.1 0.2
-0.1 0.6 0.1 0.2
0.3 0.2 0 0.12
0.6 0.5 0 0

-1.0 1.6 -0.6 0.12
-0.3 1.9 -0.4 0.12
0.4 1.5 -0.6 0.12
1.0 1.8 -0.5 0.12
"""


@pytest.fixture(scope="module")
def scene_and_reference(tmp_path_factory):
    d = tmp_path_factory.mktemp("curves")
    (d / "zigzag.txt").write_text(ZIGZAG)
    (d / "waves.txt").write_text(WAVES)
    xml = d / "curves.xml"
    xml.write_text(SCENE.replace("@SENSOR@", sensor(50, "0,1.3,3.4", "0,0.8,0")))
    return xml, mitsuba_render(xml, OUT / "mitsuba_curves.exr", spp=1024, seed=2)


def test_curves_render_as_mitsuba_does(scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    img = neepp_agrees(xml, ref, "path", 256, neepp_bin, OUT)
    assert_blocks_agree(img, ref, (xml.stem, "path"), block=4)
