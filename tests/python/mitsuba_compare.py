"""Shared by the tests that render a small scene of the project's own with Mitsuba 3 and with neepp and
compare the images: Mitsuba's render (scalar_rgb, no LLVM needed) and the agreement test (the mean within
a relative tolerance plus 4 standard errors, and each of 3 x 3 regions within a wider one), optionally
with a per-block z-test of the pixel differences."""
from __future__ import annotations

import subprocess

import numpy as np

from neepp_tools import exr, metrics, runner

# The camera and film both test scenes use: 48 x 36 pixels, box filter, the sample count as $spp.
SENSOR = """<sensor type="perspective"><float name="fov" value="@FOV@"/>
    <transform name="to_world"><lookat origin="@ORIGIN@" target="@TARGET@" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="36"/><rfilter type="box"/></film>
  </sensor>"""


def slide() -> np.ndarray:
    """A 6 x 3 RGB image for projected-light tests: a bright corner, a dark column and colours that differ
    left to right and top to bottom, so a mirrored, flipped or stretched projection shows."""
    img = np.full((3, 6, 3), 0.3, np.float32)
    img[0, 0] = (3.0, 2.5, 2.0)
    img[:, 4] = 0.0
    img[2, :, 0] = 1.2
    img[:, 1, 2] = 1.5
    return img


def sensor(fov: float, origin: str, target: str) -> str:
    return SENSOR.replace("@FOV@", str(fov)).replace("@ORIGIN@", origin).replace("@TARGET@", target)


# The bump- and normal-map tests' scene: a rough plastic plane under a perturbed shading frame (the
# perturbing <bsdf> opens as @OPEN@, its flags at @FLAGS@), lit at a grazing angle by a small area light,
# with a dim sky.
PERTURBED_PLANE = """<scene version="3.0.0">
  <default name="spp" value="64"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="1.5"/><rotate x="1" angle="-90"/></transform>
    @OPEN@@FLAGS@
      <bsdf type="roughplastic"><float name="alpha" value="0.15"/><rgb name="diffuse_reflectance" value="0.6,0.5,0.4"/></bsdf>
    </bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate y="1" angle="-90"/><translate x="2.5" y="0.25"/></transform>
    <emitter type="area"><rgb name="radiance" value="40"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.05"/></emitter>
</scene>
"""
# Mitsuba's two defaults of both, on and off.
PERTURBED_FLAGS = {"defaults": "",
                   "off": '<boolean name="flip_invalid_normals" value="false"/><boolean name="use_shadowing_function" value="false"/>'}


def perturbed_plane(opening: str, flags: str) -> str:
    """PERTURBED_PLANE with its perturbing BSDF's opening (through the map's texture) and flags, seen from
    above at 45°."""
    return (PERTURBED_PLANE.replace("@OPEN@", opening).replace("@FLAGS@", flags)
            .replace("@SENSOR@", sensor(45, "0,2.5,2.5", "0,0,0")))


def mitsuba_render(xml, out, spp: int, seed: int):
    """Mitsuba 3's image of the scene file (RGB)."""
    out.parent.mkdir(parents=True, exist_ok=True)
    code = ("import os, mitsuba as mi; mi.set_variant('scalar_rgb'); "
            f"img = mi.render(mi.load_file({str(xml)!r}), spp={spp}, seed={seed}); "
            f"mi.Bitmap(img).write({str(out)!r}); os._exit(0)")
    subprocess.run([runner.mitsuba_python(), "-c", code], check=True, timeout=600)
    return exr.read_exr(out)[..., :3]


def scene_and_mitsuba(folder, name: str, scene: str, out_dir, spp: int = 1024, seed: int = 1):
    """Writes the scene text to folder/NAME.xml and renders it with Mitsuba 3 into out_dir: (xml, image), the
    module-scoped fixture of an image test against Mitsuba."""
    xml = folder / f"{name}.xml"
    xml.write_text(scene)
    return xml, mitsuba_render(xml, out_dir / f"mitsuba_{name}.exr", spp=spp, seed=seed)


def assert_agrees(img, ref, what, mean_tol: float = 0.01, region_tol: float = 0.02):
    img, ref = img[..., :3], ref[..., :3]
    m, mr = metrics.image_mean(img), metrics.image_mean(ref)
    se = metrics.mean_stderr(img, ref, block=4)
    assert abs(m - mr) < 4 * se + mean_tol * mr, (what, m, mr, se)
    h, w = img.shape[0] // 3, img.shape[1] // 3
    for i in range(3):
        for j in range(3):
            a, b = img[i * h:(i + 1) * h, j * w:(j + 1) * w], ref[i * h:(i + 1) * h, j * w:(j + 1) * w]
            ma, mb, s = metrics.image_mean(a), metrics.image_mean(b), metrics.mean_stderr(a, b, block=4)
            assert abs(ma - mb) < 4 * s + region_tol * mb + 1e-4, (what, i, j, ma, mb, s)


def assert_blocks_agree(img, ref, what, block: int = 12, level: float = 0.01):
    """Every block x block tile passes a z-test of its pixel differences (Sidak-corrected, all tiles together
    failing with probability `level` when the images agree). assert_agrees's standard errors come from the
    spread of the difference over tiles, which a structural difference inflates as well (a normal map read
    mirrored can pass it); here each tile's variance comes from its own pixels, and a structural difference
    shows as a shifted tile mean."""
    frac, z_crit, n = metrics.block_agreement(img[..., :3], ref[..., :3], block, level)
    z = metrics.block_z_scores(img[..., :3], ref[..., :3], block)
    assert frac == 1.0, (what, f"{n - round(frac * n)} of {n} blocks beyond |z| {z_crit:.2f}", z.round(1).tolist())


def assert_tiles_within(img, ref, what, block: int = 6, rel_tol: float = 0.05, abs_tol: float = 0.005):
    """Each block x block tile's mean within rel_tol of the reference's plus abs_tol. assert_agrees takes
    its error bars from the difference image, so a difference in shape inside a region (an object moved or
    swapped) widens its own tolerance; a fixed one per tile does not, and catches it."""
    def tiles(x):
        x = x[..., :3].mean(axis=-1)
        h, w = (x.shape[0] // block) * block, (x.shape[1] // block) * block
        return x[:h, :w].reshape(h // block, block, w // block, block).mean(axis=(1, 3))
    a, b = tiles(img), tiles(ref)
    bad = np.argwhere(np.abs(a - b) > rel_tol * b + abs_tol)
    assert len(bad) == 0, (what, [(int(i), int(j), float(a[i, j]), float(b[i, j])) for i, j in bad[:5]])


def neepp_agrees(xml, ref, integrator: str, spp: int, neepp_bin, out_dir, blocks: bool = False):
    """neepp's render of the scene file with the integrator agrees with Mitsuba's image (assert_agrees, and
    assert_blocks_agree when blocks); returns it."""
    r = runner.run_neepp(xml, out_dir / f"neepp_{xml.stem}_{integrator}.exr", spp=spp, seed=3, binary=neepp_bin,
                         integrator=integrator)
    assert (r.image == r.image).all(), "NaN in the image"
    assert_agrees(r.image, ref, (xml.stem, integrator))
    if blocks:
        assert_blocks_agree(r.image, ref, (xml.stem, integrator))
    return r.image
