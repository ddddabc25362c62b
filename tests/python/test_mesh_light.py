"""An area light on a mesh with vertex normals emits as in Mitsuba 3: from the side its *shading* normal
faces. On a coarse, smooth-shaded ball a face and its interpolated normal disagree near the silhouette;
emitting by the faces made this scene 4.1 % brighter than Mitsuba's (1.9 % with a ball of 8x5 facets).
The light seen directly and next event estimation (with power and light-BVH selection, beside a second
light) are compared with Mitsuba at equal spp, two seeds each: image means within 4 standard errors
(the noise from each renderer's seed pair, over 8x8 tiles) plus 0.3 %.
"""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from neepp_tools import metrics, runner

W, H, SPP = 64, 48, 512


def _ball_obj(path: Path, nu: int = 6, nv: int = 4) -> None:
    """A UV sphere of nu x nv facets whose vertex normals are the exact sphere's: coarse but smooth-shaded."""
    verts = [(0.0, 0.0, 1.0)]
    for j in range(1, nv):
        th = math.pi * j / nv
        verts += [(math.sin(th) * math.cos(2 * math.pi * i / nu), math.sin(th) * math.sin(2 * math.pi * i / nu),
                   math.cos(th)) for i in range(nu)]
    verts.append((0.0, 0.0, -1.0))

    def ring(j: int, i: int) -> int:  # 0-based index of vertex i of ring j
        return 1 + (j - 1) * nu + i % nu

    faces = [(0, ring(1, i), ring(1, i + 1)) for i in range(nu)]
    for j in range(1, nv - 1):
        for i in range(nu):
            faces += [(ring(j, i), ring(j + 1, i), ring(j + 1, i + 1)), (ring(j, i), ring(j + 1, i + 1), ring(j, i + 1))]
    faces += [(ring(nv - 1, i), len(verts) - 1, ring(nv - 1, i + 1)) for i in range(nu)]
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in verts] + [f"vn {x:.6f} {y:.6f} {z:.6f}" for x, y, z in verts]
    lines += ["f " + " ".join(f"{k + 1}//{k + 1}" for k in f) for f in faces]
    path.write_text("\n".join(lines) + "\n")


def _scene(tmp: Path) -> Path:
    _ball_obj(tmp / "ball.obj")
    xml = tmp / "scene.xml"
    xml.write_text(f"""<scene version="3.0.0">
  <default name="spp" value="16"/><default name="resx" value="{W}"/><default name="resy" value="{H}"/>
  <default name="max_depth" value="2"/><default name="integrator" value="path"/>
  <integrator type="$integrator"><integer name="max_depth" value="$max_depth"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0,2.5,5" target="0,0.6,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="$resx"/><integer name="height" value="$resy"/><rfilter type="box"/></film>
  </sensor>
  <shape type="obj">
    <string name="filename" value="{tmp / 'ball.obj'}"/>
    <transform name="to_world"><rotate x="1" angle="90"/><scale value="0.6"/><translate y="1.2"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
    <emitter type="area"><rgb name="radiance" value="5"/></emitter>
  </shape>
  <shape type="rectangle">
    <transform name="to_world"><scale value="4"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf>
  </shape>
  <shape type="rectangle">
    <transform name="to_world"><scale value="0.3"/><rotate x="1" angle="90"/><translate x="2.5" y="2.5" z="-1"/></transform>
    <emitter type="area"><rgb name="radiance" value="2"/></emitter>
  </shape>
</scene>
""")
    return xml


@pytest.fixture(scope="module")
def mesh_light(tmp_path_factory, mitsuba_variant):
    tmp = tmp_path_factory.mktemp("mesh_light")
    xml = _scene(tmp)
    refs = [runner.run_mitsuba(xml, tmp / f"mitsuba{seed}.exr", variant=mitsuba_variant, resx=W, resy=H, spp=SPP,
                               max_depth=2, seed=seed, timeout=600).image for seed in (3, 4)]
    return tmp, xml, refs


@pytest.mark.parametrize("light_sampler", ["power", "bvh"])
def test_mesh_light_emits_from_its_shading_normals_front(mesh_light, light_sampler, neepp_bin):
    tmp, xml, refs = mesh_light
    imgs = [runner.run_neepp(xml, tmp / f"neepp_{light_sampler}{seed}.exr", spp=SPP, resx=W, resy=H, max_depth=2,
                             seed=seed, integrator_args={"light_sampler": light_sampler}, binary=neepp_bin,
                             timeout=600).image for seed in (5, 6)]
    floor = slice(H // 2, H)  # rows below the ball: lit only through next event estimation and MIS
    for what, rows in [("image", slice(0, H)), ("floor", floor)]:
        a, b = [i[rows] for i in imgs], [r[rows] for r in refs]
        m, mr = (metrics.image_mean(a[0]) + metrics.image_mean(a[1])) / 2, (metrics.image_mean(b[0]) + metrics.image_mean(b[1])) / 2
        # Noise alone, from each renderer's two seeds (the tiles of one render against the other's): a
        # bias between the renderers, which varies over the image, does not inflate it.
        se = math.hypot(metrics.mean_stderr(a[0], a[1]), metrics.mean_stderr(b[0], b[1])) / 2
        msg = f"{what} ({light_sampler}): neepp {m:.5g}, Mitsuba {mr:.5g}, {(m - mr) / mr:+.3%}, standard error {se / mr:.3%}"
        print(msg)
        assert abs(m - mr) < 4 * se + 0.003 * mr, msg
