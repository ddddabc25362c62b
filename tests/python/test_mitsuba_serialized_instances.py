"""Mitsuba 3's `serialized` meshes and `shapegroup`/`instance`: a scene of the project's own rendered by
neepp and by Mitsuba 3 agrees (the mean within 1 % plus 4 standard errors, each of 3 x 3 regions within 2 %,
and each 6 x 6 pixel tile within 5 %: the group's pyramid swapped for the torus by a wrong shape_index, an
instance's scale or the pyramid's face_normals left out, or a sphere's uv that ignores its rotation, each
fail that).
The .serialized file is written here in Mitsuba's layout (version 4, the pip Mitsuba has no writer): two
meshes, a textured torus with normals and uvs in single precision, and a pyramid without normals in double
precision with vertex colours, so that the offset table, both precisions and the skipped colours show.
The pyramid (faceted) and a sphere turned on its side, whose texture shows its axes, form a group instanced
twice, turned and scaled, beside the torus placed directly."""
from __future__ import annotations

import math
import struct
import zlib

import pytest

from mitsuba_compare import assert_tiles_within, mitsuba_render, neepp_agrees, sensor
from neepp_tools import REPO_ROOT

OUT = REPO_ROOT / ".cache" / "test_mitsuba_serialized_instances"


def serialized_mesh(positions, indices, normals=None, uvs=None, colors=None, double=False) -> bytes:
    """One mesh of a version 4 file: the uncompressed header, then its zlib stream."""
    flags = (0x1 if normals else 0) | (0x2 if uvs else 0) | (0x8 if colors else 0) | (0x2000 if double else 0x1000)
    real = "d" if double else "f"
    raw = struct.pack("<I", flags) + b"mesh\0" + struct.pack("<QQ", len(positions), len(indices))
    for rows in (positions, normals, uvs, colors):
        if rows:
            raw += struct.pack(f"<{len(rows) * len(rows[0])}{real}", *(x for row in rows for x in row))
    raw += struct.pack(f"<{3 * len(indices)}I", *(i for tri in indices for i in tri))
    return struct.pack("<HH", 0x041C, 4) + zlib.compress(raw)


def serialized_file(meshes) -> bytes:
    """Meshes one after another, then each one's offset and their count."""
    data, offsets = b"", []
    for mesh in meshes:
        offsets.append(len(data))
        data += mesh
    return data + struct.pack(f"<{len(offsets)}QI", *offsets, len(offsets))


def torus(major=0.35, minor=0.15, nu=24, nv=12):
    positions, normals, uvs, indices = [], [], [], []
    for i in range(nu + 1):
        for j in range(nv + 1):
            u, v = 2 * math.pi * i / nu, 2 * math.pi * j / nv
            n = (math.cos(u) * math.cos(v), math.sin(v), math.sin(u) * math.cos(v))
            positions.append((major * math.cos(u) + minor * n[0], minor * n[1], major * math.sin(u) + minor * n[2]))
            normals.append(n)
            uvs.append((i / nu, j / nv))
    for i in range(nu):
        for j in range(nv):
            a, b = i * (nv + 1) + j, (i + 1) * (nv + 1) + j
            indices += [(a, a + 1, b), (b, a + 1, b + 1)]
    return serialized_mesh(positions, indices, normals=normals, uvs=uvs)


def pyramid():
    positions = [(-0.4, 0, -0.4), (0.4, 0, -0.4), (0.4, 0, 0.4), (-0.4, 0, 0.4), (0, 0.7, 0)]
    indices = [(0, 4, 1), (1, 4, 2), (2, 4, 3), (3, 4, 0), (0, 1, 2), (0, 2, 3)]
    colors = [(1, 0, 0)] * len(positions)
    return serialized_mesh(positions, indices, colors=colors, double=True)


SCENE = """<scene version="3.0.0">
  <default name="spp" value="16"/>
  <integrator type="path"><integer name="max_depth" value="5"/></integrator>
  @SENSOR@
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.15"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.6"/><rotate x="1" angle="90"/><translate y="2.2"/></transform>
    <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
  <shape type="serialized"><string name="filename" value="meshes.serialized"/>
    <transform name="to_world"><rotate x="1" angle="30"/><translate y="0.9" z="0.3"/></transform>
    <bsdf type="diffuse"><texture name="reflectance" type="checkerboard"><rgb name="color0" value="0.8,0.7,0.2"/>
      <rgb name="color1" value="0.1,0.3,0.6"/><transform name="to_uv"><scale x="8" y="4"/></transform></texture></bsdf></shape>
  <shape type="shapegroup" id="group">
    <shape type="serialized"><string name="filename" value="meshes.serialized"/><integer name="shape_index" value="1"/>
      <boolean name="face_normals" value="true"/>
      <bsdf type="roughplastic"><float name="alpha" value="0.2"/><rgb name="diffuse_reflectance" value="0.2,0.6,0.3"/></bsdf></shape>
    <shape type="sphere"><float name="radius" value="0.3"/>
      <transform name="to_world"><rotate x="1" angle="90"/><translate x="0.7" y="0.3"/></transform>
      <bsdf type="diffuse"><texture name="reflectance" type="checkerboard"><rgb name="color0" value="0.9,0.2,0.2"/>
        <rgb name="color1" value="0.9,0.9,0.8"/><transform name="to_uv"><scale x="2"/></transform></texture></bsdf></shape>
  </shape>
  <shape type="instance"><ref id="group"/>
    <transform name="to_world"><rotate y="1" angle="25"/><translate x="-0.9" z="-0.4"/></transform></shape>
  <shape type="instance"><ref id="group"/>
    <transform name="to_world"><scale value="0.8"/><rotate y="1" angle="-70"/><translate x="0.8" z="-0.2"/></transform></shape>
</scene>
"""


@pytest.fixture(scope="module")
def scene_and_reference(tmp_path_factory):
    folder = tmp_path_factory.mktemp("serialized_instances")
    (folder / "meshes.serialized").write_bytes(serialized_file([torus(), pyramid()]))
    xml = folder / "serialized_instances.xml"
    xml.write_text(SCENE.replace("@SENSOR@", sensor(40, "0,1.4,2.6", "0,0.55,-0.2")))
    return xml, mitsuba_render(xml, OUT / "mitsuba_serialized_instances.exr", spp=1024, seed=2)


def test_renders_as_mitsuba_does(scene_and_reference, neepp_bin):
    xml, ref = scene_and_reference
    img = neepp_agrees(xml, ref, "path", 256, neepp_bin, OUT)
    assert_tiles_within(img, ref, xml.stem)
