"""Mitsuba 3 centres an environment map's texel i at u = (i + 1/2) / W (its envmap shifts the lookup by
half a texel); neepp put it at i / W, turning every map by half a texel in azimuth (0.70° on a 256-wide
map: 2 % on a published scene's window region, coloured stripes in Mitsuba's mirror-sphere tests). The
camera looks straight at a coarse map of coloured columns, where half a texel is 11°: neepp's image
must equal Mitsuba 3's pixel for pixel (up to the antialiasing noise of 64 spp)."""
from __future__ import annotations

import numpy as np

from neepp_tools import REPO_ROOT, exr, runner

OUT = REPO_ROOT / ".cache" / "test_envmap_convention"


def test_envmap_texels_sit_where_mitsuba_puts_them(tmp_path, neepp_bin, mitsuba_variant):
    cols = np.array([[1, 0.1, 0.1], [0.1, 1, 0.1], [0.1, 0.1, 1], [1, 1, 0.1]], dtype=np.float32)
    env = np.tile(cols[np.arange(16) % 4][None, :, :], (8, 1, 1))  # 16 x 8, columns cycling red, green, blue, yellow
    env[:, 5] = (4, 4, 4)  # one bright column, so a shift cannot hide behind the cycle's period
    exr.write_exr(tmp_path / "env.exr", env)
    xml = tmp_path / "scene.xml"
    xml.write_text("""<scene version="3.0.0">
  <default name="resx" value="64"/><default name="resy" value="32"/><default name="spp" value="16"/>
  <default name="max_depth" value="1"/><default name="integrator" value="path"/>
  <integrator type="$integrator"><integer name="max_depth" value="$max_depth"/></integrator>
  <sensor type="perspective"><float name="fov" value="100"/>
    <transform name="to_world"><lookat origin="0,0,0" target="0.3,0.1,-1" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="$resx"/><integer name="height" value="$resy"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="envmap"><string name="filename" value="env.exr"/></emitter>
</scene>
""")
    ref = runner.run_mitsuba(xml, OUT / "mitsuba.exr", variant=mitsuba_variant, spp=64, max_depth=1, seed=1).image
    img = runner.run_neepp(xml, OUT / "neepp.exr", spp=64, max_depth=1, seed=1, binary=neepp_bin).image
    diff = np.abs(img - ref)
    assert ref.mean() > 0.3
    assert diff.mean() < 0.01 * ref.mean() and diff.max() < 0.15 * ref.max(), (diff.mean(), diff.max())
