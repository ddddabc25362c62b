"""<spectrum> given as wavelength:value pairs, as a .spd file or as a constant becomes the RGB Mitsuba 3's
RGB variants make of it, within 0.5 %: as a reflectance (seen under D65, clamped to [0, 1]) and as an
emitter's radiance (taken as it is: a constant is equal-energy light, purple-ish in sRGB). Mitsuba's
value is its texture's, read with mi.traverse from the pip package (scalar_rgb); neepp's is read off
renders that show it exactly (no noise): a constant environment seen directly gives its radiance, and a
diffuse plane under a white environment of radiance 1, traced by BSDF sampling with one bounce, gives
its reflectance in every pixel."""
from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from neepp_tools import REPO_ROOT, runner

OUT = REPO_ROOT / ".cache" / "test_spectrum_vs_mitsuba"

SPECTRA = {
    "pairs": "400:0.1, 500:0.5, 600:0.8",
    "flat": "360:1, 830:1",
    "purple": "450:0.9, 550:0.05, 650:0.9",
    "uneven": "380:0.2,420:0.9,470:0.3,700:0.95,780:0.1",
    "constant": "0.5",
    "bright": "550:3, 600:5",  # out of gamut: clamped to [0, 1] as a reflectance, to >= 0 as a radiance
    "file": "@SPD@",
}
SPD = "# a spectrum file as Mitsuba reads it\n400 0.2\n\n500 0.7\n600 0.4\n700 0.9\n"

CAMERA = """<sensor type="orthographic"><transform name="to_world"><lookat origin="0,0,1" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="1"/></sampler>
    <film type="hdrfilm"><integer name="width" value="2"/><integer name="height" value="2"/><rfilter type="box"/></film></sensor>"""


def spectrum_xml(key: str, name: str, spd) -> str:
    return (f'<spectrum name="{name}" filename="{spd}"/>' if key == "file"
            else f'<spectrum name="{name}" value="{SPECTRA[key]}"/>')


def mitsuba_values(tmp_path, spd) -> dict:
    """{key: (reflectance rgb, emission rgb)} from Mitsuba's textures."""
    code = ["import json, mitsuba as mi", "mi.set_variant('scalar_rgb')", "out = {}"]
    for key in SPECTRA:
        refl = f'<bsdf version="3.0.0" type="diffuse">{spectrum_xml(key, "reflectance", spd)}</bsdf>'
        emit = f'<emitter version="3.0.0" type="constant">{spectrum_xml(key, "radiance", spd)}</emitter>'
        code.append(f"r = mi.traverse(mi.load_string({refl!r}))['reflectance.value']")
        code.append(f"e = mi.traverse(mi.load_string({emit!r}))['radiance.value']")
        code.append(f"out[{key!r}] = [[float(v) for v in (r if hasattr(r, '__len__') else [r] * 3)], [float(v) for v in e]]")
    code.append("print('RESULT ' + json.dumps(out))")  # after Mitsuba's log lines (its clamping warnings)
    out = subprocess.run([runner.mitsuba_python(), "-c", "\n".join(code)], check=True, capture_output=True, text=True,
                         timeout=300).stdout
    values = json.loads(out.split("RESULT ", 1)[1])
    return {k: (np.array(v[0]), np.array(v[1])) for k, v in values.items()}


def neepp_pixel(xml_text: str, path, neepp_bin) -> np.ndarray:
    path.write_text(xml_text)
    img = runner.run_neepp(path, path.with_suffix(".exr"), spp=1, binary=neepp_bin, integrator="path",
                           integrator_args={"nee": "false", "max_depth": 2}).image[..., :3]
    assert np.allclose(img, img[0, 0], rtol=1e-5), img  # every pixel the same, exactly
    return img[0, 0]


def test_spectra_convert_as_mitsuba_does(tmp_path, neepp_bin):
    spd = tmp_path / "test.spd"
    spd.write_text(SPD)
    ref = mitsuba_values(tmp_path, spd)
    for key in SPECTRA:
        emission = neepp_pixel(f"""<scene version="3.0.0">{CAMERA}
  <emitter type="constant">{spectrum_xml(key, "radiance", spd)}</emitter></scene>""", tmp_path / f"e_{key}.xml", neepp_bin)
        reflectance = neepp_pixel(f"""<scene version="3.0.0">{CAMERA}
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="rectangle"><bsdf type="diffuse">{spectrum_xml(key, "reflectance", spd)}</bsdf></shape></scene>""",
                                  tmp_path / f"r_{key}.xml", neepp_bin)
        for what, got, want in (("reflectance", reflectance, ref[key][0]), ("emission", emission, ref[key][1])):
            assert np.allclose(got, want, rtol=5e-3, atol=1e-4), (key, what, got, want)
