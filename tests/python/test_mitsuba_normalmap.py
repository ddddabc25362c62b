"""Mitsuba 3's `normalmap` with its two defaults, `flip_invalid_normals` and `use_shadowing_function`, on
and off: a rough plastic plane whose tangent-space normals (an EXR written here at run time, read raw) lean
up to ~50° along both tangents, lit at a grazing angle, rendered by neepp's path tracer, BDPT and light
tracer agrees with Mitsuba 3's: the mean within 1 % plus 4 standard errors, each of 3 x 3 regions within
2 % plus 4 standard errors, and every 12 x 12 block of pixel differences passing a z-test (which catches a
map read mirrored along either tangent, or a flip left out). Light tracing and BDPT go through the same
frame rules in importance transport as the bump map does."""
from __future__ import annotations

import numpy as np
import pytest

from mitsuba_compare import PERTURBED_FLAGS, mitsuba_render, neepp_agrees, perturbed_plane
from neepp_tools import REPO_ROOT, exr

OUT = REPO_ROOT / ".cache" / "test_mitsuba_normalmap"

OPENING = """<bsdf type="normalmap">
      <texture name="normalmap" type="bitmap"><string name="filename" value="normals.exr"/><boolean name="raw" value="true"/></texture>"""


def normal_map(size: int = 96) -> np.ndarray:
    """Tangent-space normals, x varying along u and y along v, both leaning one way on average (so that a
    turned or mirrored tangent frame shows), encoded as (n + 1) / 2."""
    u = (np.arange(size) + 0.5) / size
    nx = 0.3 + 0.6 * np.sin(2 * np.pi * 3 * u)[None, :].repeat(size, 0)
    ny = 0.4 + 0.5 * np.cos(2 * np.pi * 2 * u)[:, None].repeat(size, 1)
    n = np.stack([nx, ny, np.ones_like(nx)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return ((n + 1) / 2).astype(np.float32)


@pytest.fixture(scope="module", params=list(PERTURBED_FLAGS))
def scene_and_reference(request, tmp_path_factory):
    folder = tmp_path_factory.mktemp("normalmap")
    exr.write_exr(folder / "normals.exr", normal_map())
    xml = folder / f"{request.param}.xml"
    xml.write_text(perturbed_plane(OPENING, PERTURBED_FLAGS[request.param]))
    return xml, mitsuba_render(xml, OUT / f"mitsuba_{request.param}.exr", spp=1024, seed=1)


@pytest.mark.parametrize("integrator", ["path", "bdpt", "light"])
def test_normal_maps_shade_as_in_mitsuba(integrator, scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    neepp_agrees(xml, ref, integrator, 1024, neepp_bin, OUT, blocks=True)
