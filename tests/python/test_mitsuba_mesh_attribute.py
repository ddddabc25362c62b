"""Mitsuba 3's `mesh_attribute` texture on PLY attributes: a small scene of the project's own (a tilted 4 x 4
grid whose vertex colours vary across it, read as its reflectance through `vertex_color`, and a second grid
whose faces each have their own colour, `face_tint_color`, scaled, on a floor under an area light and a dim
sky) rendered by neepp's path tracer agrees with Mitsuba 3's image: the mean within 1 % plus 4 standard
errors, each of 3 x 3 regions within 2 % plus 4 standard errors, and every 4 x 4 block's z-test (so
attributes on the wrong vertices or faces, or mis-grouped channels, show)."""
from __future__ import annotations

import pytest

from mitsuba_compare import assert_blocks_agree, mitsuba_render, neepp_agrees, sensor
from neepp_tools import REPO_ROOT

OUT = REPO_ROOT / ".cache" / "test_mitsuba_mesh_attribute"
N = 4  # vertices per side of each grid: cells of a few pixels, so that 4 x 4 blocks see their triangles

SCENE = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  @SENSOR@
  <shape type="ply"><string name="filename" value="grid.ply"/>
    <transform name="to_world"><rotate y="1" angle="25"/><translate x="-0.7" y="0.1" z="-0.2"/></transform>
    <bsdf type="diffuse"><texture name="reflectance" type="mesh_attribute"><string name="name" value="vertex_color"/></texture></bsdf>
  </shape>
  <shape type="ply"><string name="filename" value="grid.ply"/>
    <transform name="to_world"><rotate y="1" angle="-30"/><translate x="0.6" y="0.1" z="-0.1"/></transform>
    <bsdf type="diffuse"><texture name="reflectance" type="mesh_attribute"><string name="name" value="face_tint_color"/>
      <float name="scale" value="0.8"/></texture></bsdf>
  </shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.4"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="2.2" z="0.8"/></transform>
    <emitter type="area"><rgb name="radiance" value="6"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>
</scene>
"""


def grid_ply() -> str:
    """An N x N vertex grid (1.2 wide, upright, facing +z) with r g b per vertex and tint_r/g/b per triangle
    (face_tint_color, by Mitsuba's naming), the values varied enough that a shifted index shows."""
    verts, faces = [], []
    for j in range(N):
        for i in range(N):
            s, t = i / (N - 1), j / (N - 1)
            verts.append(f"{1.2 * s - 0.6:.4f} {1.2 * t:.4f} 0 {s:.3f} {t:.3f} {abs(s - t) * 0.9:.3f}")
    k = 0
    for j in range(N - 1):
        for i in range(N - 1):
            a = j * N + i
            for tri in ((a, a + 1, a + N + 1), (a, a + N + 1, a + N)):
                # The two triangles of a cell far apart in colour, the cells varying too.
                c = (0.9, 0.2 + 0.1 * (k // 2 % 5), 0.1) if k % 2 == 0 else (0.1, 0.3 + 0.1 * (k // 2 % 4), 0.9)
                faces.append(f"3 {tri[0]} {tri[1]} {tri[2]} {c[0]:.3f} {c[1]:.3f} {c[2]:.3f}")
                k += 1
    header = (f"ply\nformat ascii 1.0\nelement vertex {len(verts)}\nproperty float x\nproperty float y\n"
              "property float z\nproperty float r\nproperty float g\nproperty float b\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nproperty float tint_r\n"
              "property float tint_g\nproperty float tint_b\nend_header\n")
    return header + "\n".join(verts + faces) + "\n"


@pytest.fixture(scope="module")
def scene_and_reference(tmp_path_factory):
    d = tmp_path_factory.mktemp("mesh_attribute")
    (d / "grid.ply").write_text(grid_ply())
    xml = d / "mesh_attribute.xml"
    xml.write_text(SCENE.replace("@SENSOR@", sensor(55, "0,1.0,3.2", "0,0.6,0")))
    return xml, mitsuba_render(xml, OUT / "mitsuba_mesh_attribute.exr", spp=1024, seed=2)


def test_mesh_attributes_render_as_mitsuba_does(scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    img = neepp_agrees(xml, ref, "path", 256, neepp_bin, OUT)
    assert_blocks_agree(img, ref, (xml.stem, "path"), block=4)
