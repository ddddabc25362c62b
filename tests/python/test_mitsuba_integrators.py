"""A scene that names one of Mitsuba 3's integrators renders, in neepp, the image Mitsuba 3 renders with
it: volpath as neepp's volpath and volpathmis as volpath (no media here), direct as path with max_depth 2 (a glossy room where the second
bounce is a third of the light, so a wrong depth shows), aov as the integrator it nests (its RGB image; the
AOV channels are not written). Image means within 1.5 % plus 4 standard errors. (prb maps to path too;
Mitsuba has it only in its differentiable variants, which this test does not start.)"""
from __future__ import annotations

import subprocess

import pytest

from neepp_tools import REPO_ROOT, exr, metrics, runner

OUT = REPO_ROOT / ".cache" / "test_mitsuba_integrators"

SCENE = """<scene version="3.0.0">
  <default name="resx" value="32"/><default name="resy" value="24"/><default name="spp" value="16"/>
  <integrator type="@TYPE@">@OPTIONS@</integrator>
  <sensor type="perspective"><float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,1,1.9" target="0,0.8,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="$resx"/><integer name="height" value="$resy"/><rfilter type="box"/></film>
  </sensor>
  <shape type="cube"><transform name="to_world"><scale value="2"/><translate y="1"/></transform>
    <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.3" y="0.5" z="0"/><float name="radius" value="0.4"/>
    <bsdf type="roughplastic"><float name="alpha" value="0.2"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="2.9"/></transform>
    <emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
</scene>
"""


@pytest.mark.parametrize("mitsuba_type, options", [
    ("direct", ""),
    ("volpathmis", '<integer name="max_depth" value="4"/>'),
    ("volpath", '<integer name="max_depth" value="3"/>'),
    # aov's image is its nested integrator's (the AOV channels neepp does not write).
    ("aov", '<string name="aovs" value="dd.y:depth, nn:sh_normal"/>'
            '<integrator type="path" name="image"><integer name="max_depth" value="3"/></integrator>'),
])
def test_scene_integrator_renders_as_in_mitsuba(mitsuba_type, options, tmp_path, neepp_bin):
    xml = tmp_path / "scene.xml"
    xml.write_text(SCENE.replace("@TYPE@", mitsuba_type).replace("@OPTIONS@", options))
    # Mitsuba with the scene's own integrator (runner.run_mitsuba sets one), scalar_rgb: no LLVM needed.
    out = OUT / f"mitsuba_{mitsuba_type}.exr"
    OUT.mkdir(parents=True, exist_ok=True)
    code = ("import os, mitsuba as mi; mi.set_variant('scalar_rgb'); "
            f"img = mi.render(mi.load_file({str(xml)!r}), spp=256, seed=2); "
            f"import numpy as np; mi.Bitmap(np.array(img)[..., :3]).write({str(out)!r}); os._exit(0)")  # aov: + AOVs
    subprocess.run([runner.mitsuba_python(), "-c", code], check=True, timeout=300)
    ref = exr.read_exr(out)
    r = runner.run_neepp(xml, OUT / f"neepp_{mitsuba_type}.exr", spp=256, seed=2, binary=neepp_bin)
    mapped = {"volpath": None, "volpathmis": "volpath"}.get(mitsuba_type, "path")
    assert (f"renders here as '{mapped}'" in r.log) if mapped else ("renders here as" not in r.log), r.log
    assert (mitsuba_type == "aov") == ("not written: 'aov': the AOV channels (dd.y:depth, nn:sh_normal)" in r.log), r.log
    m, mr = metrics.image_mean(r.image), metrics.image_mean(ref)
    se = metrics.mean_stderr(r.image, ref)
    assert abs(m - mr) < 4 * se + 0.015 * mr, (mitsuba_type, m, mr, se)
