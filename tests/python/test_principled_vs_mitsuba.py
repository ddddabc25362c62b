"""Mitsuba 3's `principled` and `principledthin` BSDFs render in neepp as in Mitsuba 3: a small room of
the project's own with five principled objects (an anisotropic tinted metal box; a transmissive sphere
with clearcoat and sheen; a sphere with a checkerboard base_color and roughness, flatness, sheen and
`specular`; Mitsuba's documentation example, every lobe with spec_trans and anisotropy, on a sphere; a
wall with no parameters at all) and a principledthin panel (diffuse and specular transmission, textured),
lit by a ceiling panel. neepp's `path` and `bdpt` (whose light subpaths evaluate the BSDFs in importance
mode, without eta^2 through the transmissive spheres) against Mitsuba's `path` at the same size and
depth: image means within 1 %, and per 8x8 block a Sidak-corrected z-test of the difference passing on
at least 99 % of the blocks (metrics.block_agreement), so that one wrong object fails too.
The samples are spent where they buy the most power: Mitsuba's render (llvm) costs ~1/15 of neepp's bdpt
a sample, and bdpt's pixels are ~0.4x as noisy as Mitsuba path's (median 8x8 block), so Mitsuba renders
1024 spp and bdpt 384: against both at 512, the difference's variance (the z-test's denominator) is lower
in 99 % of the blocks (median 0.73x) and that of the image mean 0.81x, for ~15 CPU-s less. path keeps
512 spp (its noise is Mitsuba's), so its test only gains from Mitsuba's extra samples.
Renders go to .cache/test_principled_vs_mitsuba/; Mitsuba's is cached under .cache/mitsuba.
"""
from __future__ import annotations

import pytest

from neepp_tools import REPO_ROOT, metrics, runner

OUT = REPO_ROOT / ".cache" / "test_principled_vs_mitsuba"
W, H, MAX_DEPTH = 128, 96, 8
MITSUBA_SPP = 1024
SPP = {"path": 512, "bdpt": 384}  # neepp's, per integrator (see above)
MEAN_TOL = 0.01

SCENE = """<scene version="3.0.0">
  <default name="resx" value="128"/><default name="resy" value="96"/><default name="spp" value="16"/>
  <default name="max_depth" value="8"/><default name="integrator" value="path"/>
  <integrator type="$integrator"><integer name="max_depth" value="$max_depth"/></integrator>
  <sensor type="perspective"><float name="fov" value="62"/>
    <transform name="to_world"><lookat origin="0,0.5,1.9" target="0,-0.35,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="$resx"/><integer name="height" value="$resy"/>
      <rfilter type="box"/></film>
  </sensor>
  <shape type="cube"><transform name="to_world"><scale value="2"/><translate y="1"/></transform>
    <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.55, 0.5"/></bsdf></bsdf></shape>
  <shape type="rectangle">
    <transform name="to_world"><scale value="0.6"/><rotate x="1" angle="90"/><translate y="2.9"/></transform>
    <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>

  <!-- No parameters: Mitsuba's defaults. -->
  <shape type="rectangle"><transform name="to_world"><scale x="2" y="2"/><translate y="1" z="-1.98"/></transform>
    <bsdf type="principled"/></shape>

  <!-- Tinted anisotropic metal (a box: its tangents are the faces' uv directions in both renderers). -->
  <shape type="cube">
    <transform name="to_world"><scale value="0.32"/><rotate y="1" angle="35"/><translate x="-0.75" y="-0.68" z="0.45"/></transform>
    <bsdf type="principled">
      <rgb name="base_color" value="0.9, 0.6, 0.3"/>
      <float name="metallic" value="0.9"/><float name="roughness" value="0.45"/>
      <float name="anisotropic" value="0.7"/><float name="spec_tint" value="0.5"/>
    </bsdf></shape>

  <!-- Transmissive, clearcoated and sheened. -->
  <shape type="sphere"><point name="center" x="-0.55" y="-0.55" z="-0.55"/><float name="radius" value="0.45"/>
    <bsdf type="principled">
      <rgb name="base_color" value="0.8, 0.9, 1.0"/>
      <float name="spec_trans" value="0.8"/><float name="roughness" value="0.3"/><float name="eta" value="1.45"/>
      <float name="clearcoat" value="0.8"/><float name="clearcoat_gloss" value="0.5"/>
      <float name="sheen" value="0.6"/><float name="sheen_tint" value="0.5"/>
    </bsdf></shape>

  <!-- Textured base_color and roughness. -->
  <shape type="sphere"><point name="center" x="0.55" y="-0.55" z="-0.55"/><float name="radius" value="0.45"/>
    <bsdf type="principled">
      <texture name="base_color" type="checkerboard">
        <rgb name="color0" value="0.8, 0.2, 0.1"/><rgb name="color1" value="0.1, 0.3, 0.8"/>
        <transform name="to_uv"><scale x="6" y="3"/></transform>
      </texture>
      <texture name="roughness" type="checkerboard">
        <float name="color0" value="0.15"/><float name="color1" value="0.8"/>
        <transform name="to_uv"><scale x="4" y="4"/></transform>
      </texture>
      <float name="flatness" value="0.5"/><float name="sheen" value="0.4"/><float name="specular" value="0.7"/>
    </bsdf></shape>

  <!-- Mitsuba's documentation example: every lobe. -->
  <shape type="sphere"><point name="center" x="0.75" y="-0.62" z="0.5"/><float name="radius" value="0.38"/>
    <bsdf type="principled">
      <rgb name="base_color" value="1.0, 1.0, 1.0"/>
      <float name="metallic" value="0.7"/><float name="specular" value="0.6"/><float name="roughness" value="0.2"/>
      <float name="spec_tint" value="0.4"/><float name="anisotropic" value="0.5"/><float name="sheen" value="0.3"/>
      <float name="sheen_tint" value="0.2"/><float name="clearcoat" value="0.6"/>
      <float name="clearcoat_gloss" value="0.3"/><float name="spec_trans" value="0.4"/>
    </bsdf></shape>

  <!-- principledthin: a leaf-like panel, light passing through it diffusely and specularly. -->
  <shape type="rectangle">
    <transform name="to_world"><scale x="0.35" y="0.28"/><rotate x="1" angle="-60"/><translate x="0.05" y="-0.7" z="0.35"/></transform>
    <bsdf type="principledthin">
      <texture name="base_color" type="checkerboard">
        <rgb name="color0" value="0.3, 0.7, 0.2"/><rgb name="color1" value="0.9, 0.8, 0.3"/>
        <transform name="to_uv"><scale x="3" y="3"/></transform>
      </texture>
      <float name="diff_trans" value="1.0"/><float name="spec_trans" value="0.5"/><float name="roughness" value="0.35"/>
      <float name="eta" value="1.4"/><float name="sheen" value="0.3"/><float name="spec_tint" value="0.2"/>
    </bsdf></shape>
</scene>
"""


def scene_file():
    """The scene, rewritten only when its text changes (Mitsuba's cached render is keyed by its mtime)."""
    OUT.mkdir(parents=True, exist_ok=True)
    xml = OUT / "principled.xml"
    if not xml.exists() or xml.read_text() != SCENE:
        xml.write_text(SCENE)
    return xml


_memo: dict = {}


def mitsuba_render(variant):
    if variant not in _memo:
        _memo[variant] = runner.run_mitsuba(scene_file(), variant=variant, resx=W, resy=H, spp=MITSUBA_SPP,
                                            max_depth=MAX_DEPTH, seed=5, timeout=900, cache=True).image
    return _memo[variant]


@pytest.mark.parametrize("integrator", ["path", "bdpt"])
def test_principled_renders_as_in_mitsuba(integrator, neepp_bin, mitsuba_variant):
    ref = mitsuba_render(mitsuba_variant)
    r = runner.run_neepp(scene_file(), OUT / f"neepp_{integrator}.exr", spp=SPP[integrator], resx=W, resy=H,
                         max_depth=MAX_DEPTH, seed=9, integrator=integrator, binary=neepp_bin, timeout=900)
    m, mr = metrics.image_mean(r.image), metrics.image_mean(ref)
    se = metrics.mean_stderr(r.image, ref)
    passed, z_crit, n = metrics.block_agreement(r.image, ref)
    msg = (f"principled, {integrator} vs Mitsuba path, {W}x{H}, {SPP[integrator]} / {MITSUBA_SPP} spp: means {m:.5g} / {mr:.5g} "
           f"({m / mr - 1:+.3%}, standard error {se / mr:.3%}); {passed:.2%} of {n} blocks within |z| < {z_crit:.2f}")
    print(msg)
    assert r.log.count("warning") == 0, r.log
    assert abs(m / mr - 1) < MEAN_TOL, msg
    assert passed >= 0.99, msg
