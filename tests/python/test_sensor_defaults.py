"""Mitsuba 3's sensor without `fov`: a 50 mm focal length (35 mm film equivalent), the angle across the
frame's diagonal applied to the film's diagonal (34.0° in x on a square film), or the `focal_length`
given. neepp used 39.3° in x whatever the film, which changed the framing of every such scene (35 of the
41 scenes of Mitsuba's render suite give no fov). A dark sphere before a uniformly bright sky fills a
share of the frame that shows any difference of field of view; neepp and Mitsuba 3 must agree on the
image mean within 1 % and per 4x4 block within 0.03 (on values of 0.1 to 1; a field of view off by 5°
moves the silhouette's blocks by 0.2 or more)."""
from __future__ import annotations

import numpy as np
import pytest

from neepp_tools import REPO_ROOT, metrics, runner

OUT = REPO_ROOT / ".cache" / "test_sensor_defaults"


def scene(tmp_path, camera_extra: str) -> str:
    xml = tmp_path / "scene.xml"
    xml.write_text(f"""<scene version="3.0.0">
  <default name="resx" value="32"/><default name="resy" value="32"/><default name="spp" value="16"/>
  <default name="max_depth" value="2"/><default name="integrator" value="path"/>
  <integrator type="$integrator"><integer name="max_depth" value="$max_depth"/></integrator>
  <sensor type="perspective">{camera_extra}
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="$resx"/><integer name="height" value="$resy"/>
      <rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><float name="radius" value="1"/><bsdf type="diffuse"><rgb name="reflectance" value="0.1"/></bsdf></shape>
</scene>
""")
    return xml


@pytest.mark.parametrize("size, camera", [
    ((32, 32), ""),                                                   # square film, 34.0° in x
    ((48, 32), ""),                                                   # 3:2, 39.6° in x
    ((24, 40), ""),                                                   # portrait
    ((32, 32), '<string name="focal_length" value="35mm"/>'),
])
def test_sensor_without_fov_frames_as_mitsuba(size, camera, tmp_path, neepp_bin, mitsuba_variant):
    xml = scene(tmp_path, camera)
    w, h = size
    ref = runner.run_mitsuba(xml, OUT / f"mitsuba_{w}x{h}_{len(camera)}.exr", variant=mitsuba_variant, resx=w, resy=h,
                             spp=64, max_depth=2, seed=3).image
    img = runner.run_neepp(xml, OUT / f"neepp_{w}x{h}_{len(camera)}.exr", spp=64, resx=w, resy=h, max_depth=2,
                           seed=3, binary=neepp_bin).image
    m, mr = metrics.image_mean(img), metrics.image_mean(ref)
    assert abs(m / mr - 1) < 0.01, (m, mr)
    blocks, rblocks = metrics.downsample(img, 4).mean(-1), metrics.downsample(ref, 4).mean(-1)
    assert np.max(np.abs(blocks - rblocks)) < 0.03, np.round(blocks - rblocks, 3)


def test_malformed_focal_length_is_an_error(tmp_path, neepp_bin):
    import subprocess
    xml = scene(tmp_path, '<string name="focal_length" value="fifty"/>')
    r = subprocess.run([str(neepp_bin), "render", str(xml), "-o", str(tmp_path / "o.exr"), "--quiet"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "focal_length 'fifty'" in r.stderr and "scene.xml:" in r.stderr, r.stderr
