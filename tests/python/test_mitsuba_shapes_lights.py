"""Mitsuba 3's `disk` and `cylinder` shapes and `spot` and `directional` lights: two small scenes of the
project's own (a spot light across a floor, a tilted cylinder between p0 and p1, a disk-shaped area light
and a tilted diffuse disk; a sun-like directional light on a floor, a glossy sphere and a box) rendered by
neepp's path tracer, BDPT and light tracer agree with Mitsuba 3's images: the mean within 1 % plus 4
standard errors, and each of 3 x 3 regions within 2 % plus 4 standard errors (so a disk facing the wrong
way, a cylinder along the wrong axis, a spot's falloff or a light arriving from the wrong side shows)."""
from __future__ import annotations

import subprocess

import numpy as np
import pytest

from neepp_tools import REPO_ROOT, exr, metrics, runner

OUT = REPO_ROOT / ".cache" / "test_mitsuba_shapes_lights"

SHAPES_AND_SPOT = """<scene version="3.0.0">
  <default name="spp" value="16"/><default name="max_depth" value="5"/>
  <integrator type="path"><integer name="max_depth" value="$max_depth"/></integrator>
  <sensor type="perspective"><float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,1.2,3.2" target="0,0.6,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="36"/><rfilter type="box"/></film>
  </sensor>
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

DIRECTIONAL = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="5"/></integrator>
  <sensor type="perspective"><float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,1.2,3.2" target="0,0.6,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="36"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="0.6" z="0"/><float name="radius" value="0.5"/>
    <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="-1" y="0.3" z="-0.5"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.3,0.2"/></bsdf></shape>
  <emitter type="directional"><vector name="direction" value="0.5,-1,-0.3"/><rgb name="irradiance" value="2,1.8,1.5"/></emitter>
</scene>
"""

SCENES = {"shapes_and_spot": SHAPES_AND_SPOT, "directional": DIRECTIONAL}


@pytest.fixture(scope="module", params=list(SCENES))
def scene_and_reference(request, tmp_path_factory):
    xml = tmp_path_factory.mktemp("shapes_lights") / f"{request.param}.xml"
    xml.write_text(SCENES[request.param])
    out = OUT / f"mitsuba_{request.param}.exr"
    OUT.mkdir(parents=True, exist_ok=True)
    code = ("import os, mitsuba as mi; mi.set_variant('scalar_rgb'); "
            f"img = mi.render(mi.load_file({str(xml)!r}), spp=1024, seed=2); "
            f"mi.Bitmap(img).write({str(out)!r}); os._exit(0)")
    subprocess.run([runner.mitsuba_python(), "-c", code], check=True, timeout=600)
    return xml, exr.read_exr(out)


@pytest.mark.parametrize("integrator", ["path", "bdpt", "light"])
def test_renders_as_mitsuba_does(integrator, scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    r = runner.run_neepp(xml, OUT / f"neepp_{xml.stem}_{integrator}.exr", spp=256, seed=3, binary=neepp_bin,
                         integrator=integrator)
    img = r.image[..., :3]
    ref = ref[..., :3]
    m, mr = metrics.image_mean(img), metrics.image_mean(ref)
    se = metrics.mean_stderr(img, ref, block=4)
    assert abs(m - mr) < 4 * se + 0.01 * mr, (integrator, m, mr, se)
    h, w = img.shape[0] // 3, img.shape[1] // 3
    for i in range(3):
        for j in range(3):
            a, b = img[i * h:(i + 1) * h, j * w:(j + 1) * w], ref[i * h:(i + 1) * h, j * w:(j + 1) * w]
            ma, mb = metrics.image_mean(a), metrics.image_mean(b)
            s = metrics.mean_stderr(a, b, block=4)
            assert abs(ma - mb) < 4 * s + 0.02 * mb + 1e-4, (integrator, i, j, ma, mb, s)
    assert np.isfinite(img).all()
