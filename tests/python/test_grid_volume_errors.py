"""Broken grid volumes as a user meets them: `neepp check` and `neepp render` on a scene whose heterogeneous
medium reads a damaged or mismatched .vol file. Each must fail with an error that names the scene's line,
the .vol file and the problem, and write no image; data beyond what the header gives renders (as Mitsuba
renders it) with a warning."""
from __future__ import annotations

import struct
import subprocess

import numpy as np
import pytest


def vol(values: np.ndarray, channels: int, size=(2, 2, 2), version: int = 3, data_type: int = 1) -> bytes:
    """Mitsuba's .vol layout: header (sizes x, y, z and the channel count as given), then the values as float32."""
    return (b"VOL" + bytes([version]) + struct.pack("<5i6f", data_type, *size, channels, 0, 0, 0, 1, 1, 1)
            + np.asarray(values, dtype="<f4").tobytes())


GOOD = np.full(8, 0.5)
with_nan = GOOD.copy()
with_nan[3] = np.nan       # point (1, 1, 0)
negative = GOOD.copy()
negative[6] = -2.0         # point (0, 1, 1)
with_inf = GOOD.copy()
with_inf[1] = np.inf       # point (1, 0, 0)

BROKEN = {
    "truncated": (vol(GOOD, 1)[:-5], "truncated volume grid file"),
    "size_too_big": (vol(GOOD, 1, size=(2, 2, 3)), "the header gives 2 x 2 x 3 points of 1 channel, more values than"),
    "channels_too_many": (vol(GOOD, 3), "the header gives 2 x 2 x 2 points of 3 channels, more values than"),
    "two_channels": (vol(np.full(16, 0.5), 2), "the grid has 2 channels; a gridvolume's value is grey (1 channel) or RGB (3)"),
    "version_4": (vol(GOOD, 1, version=4), "volume grid file version 4 (only version 3 is supported)"),
    "not_float32": (vol(GOOD, 1, data_type=3), "volume grid data type 3"),
    "not_vol": (b"P6\n2 2\n255\n" + bytes(12), "not a Mitsuba volume grid (.vol) file"),
    "nan": (vol(with_nan, 1), "grid point (1, 1, 0) is nan: not a finite number"),
    "inf": (vol(with_inf, 1), "grid point (1, 0, 0) is inf: not a finite number"),
    "negative": (vol(negative, 1), "grid point (0, 1, 1) is -2.000000"),
}


def scene(tmp_path, vol_name: str):
    xml = tmp_path / "fog.xml"
    xml.write_text(f"""<scene version="3.0.0">
<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
<emitter type="constant"/>
<shape type="cube"><bsdf type="null"/><medium type="heterogeneous" name="interior">
  <volume name="sigma_t" type="gridvolume"><string name="filename" value="{vol_name}"/></volume>
</medium></shape>
</scene>
""")
    return xml


def run(neepp_bin, *args):
    return subprocess.run([str(neepp_bin), *map(str, args)], capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_broken_grid_is_refused_naming_the_file_and_the_problem(neepp_bin, tmp_path, name):
    data, problem = BROKEN[name]
    (tmp_path / f"{name}.vol").write_bytes(data)
    xml = scene(tmp_path, f"{name}.vol")
    where = f'{xml}:5: error: <volume type="gridvolume">: as "sigma_t": {tmp_path / name}.vol: '
    r = run(neepp_bin, "check", xml)
    assert r.returncode == 1, r.stdout + r.stderr
    assert where in r.stdout and problem in r.stdout, r.stdout
    out = tmp_path / "img.exr"
    r = run(neepp_bin, "render", xml, "-o", out, "--spp", 1, "--quiet")
    assert r.returncode != 0
    assert f"{tmp_path / name}.vol: " in r.stderr and problem in r.stderr, r.stderr
    assert not out.exists() and not out.with_suffix(".png").exists()


def test_data_beyond_the_header_renders_with_a_warning(neepp_bin, tmp_path):
    # Three channels' worth of values under a one-channel header: Mitsuba reads the first third.
    (tmp_path / "rgb_as_grey.vol").write_bytes(vol(np.full(24, 0.5), 1))
    xml = scene(tmp_path, "rgb_as_grey.vol")
    r = run(neepp_bin, "check", xml)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "warning" in r.stdout and "exactly 3 times as many values" in r.stdout, r.stdout
    out = tmp_path / "img.exr"
    r = run(neepp_bin, "render", xml, "-o", out, "--spp", 1, "--quiet")
    assert r.returncode == 0, r.stderr
    assert "rgb_as_grey.vol: 64 bytes after the 2 x 2 x 2 points of 1 channel" in r.stderr, r.stderr
    assert out.exists()
