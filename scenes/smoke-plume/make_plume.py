#!/usr/bin/env python3
"""Writes the smoke-plume scene's density grid, plume.vol (Mitsuba 3's .vol format, version 3), beside this file.

The grid is generated, not committed: run this script (numpy only) before rendering the scene,

    .venv/bin/python scenes/smoke-plume/make_plume.py            # -> scenes/smoke-plume/plume.vol
    .venv/bin/python scenes/smoke-plume/make_plume.py -o OUT.vol  # elsewhere

or let `neepp_tools.scene_assets.ensure_scene_assets("smoke-plume")` run it when the file is missing (the
tests do). The output is deterministic: the same bytes on every run (integer-hash value noise, no random
generator whose stream could change between numpy versions).

The plume: a column of smoke rising from a source near the bottom centre of the grid, its centre line
meandering as it rises, its radius growing from 0.07 to 0.36 of the grid's width, its density highest
low down and thinning upward, broken up by three octaves of value noise (the turbulence) and faded to zero
at the grid's faces so that the box never shows. One channel, float32, peak 1: the scene's medium scales
it (`scale`). Resolution 48 x 64 x 48 (x, y up, z); the scene maps the unit cube the grid spans to its
box with to_world.

.vol layout: b"VOL", u8 3, i32 type 1 (float32), i32 xres, yres, zres, i32 channels, 6 f32 bounding box
(xmin, ymin, zmin, xmax, ymax, zmax; the unit cube here, as Mitsuba reads the grid over [0, 1]^3 unless
use_grid_bbox is set), then the values, x fastest, then y, then z.
"""
from __future__ import annotations

import argparse
import os
import struct
from pathlib import Path

import numpy as np

RES = (48, 64, 48)  # x, y, z
SEED = 40  # issue 40


def _hash01(ix: np.ndarray, iy: np.ndarray, iz: np.ndarray, seed: int) -> np.ndarray:
    """A value in [0, 1) for each integer lattice point: a 32-bit integer hash (wrapping arithmetic)."""
    h = (ix.astype(np.uint32) * np.uint32(0x8DA6B343)) ^ (iy.astype(np.uint32) * np.uint32(0xD8163841)) \
        ^ (iz.astype(np.uint32) * np.uint32(0xCB1AB31F)) ^ np.uint32(seed * 0x9E3779B1 & 0xFFFFFFFF)
    h ^= h >> np.uint32(16)
    h *= np.uint32(0x7FEB352D)
    h ^= h >> np.uint32(15)
    h *= np.uint32(0x846CA68B)
    h ^= h >> np.uint32(16)
    return (h >> np.uint32(8)).astype(np.float64) / float(1 << 24)


def value_noise(x: np.ndarray, y: np.ndarray, z: np.ndarray, seed: int) -> np.ndarray:
    """Smooth value noise in [0, 1): lattice values from the hash, blended with a quintic fade."""
    x0, y0, z0 = np.floor(x), np.floor(y), np.floor(z)
    fx, fy, fz = x - x0, y - y0, z - z0
    fade = lambda t: t * t * t * (t * (t * 6 - 15) + 10)  # noqa: E731
    ux, uy, uz = fade(fx), fade(fy), fade(fz)
    ix, iy, iz = x0.astype(np.int64), y0.astype(np.int64), z0.astype(np.int64)
    out = np.zeros_like(x)
    for dx in (0, 1):
        wx = ux if dx else 1 - ux
        for dy in (0, 1):
            wy = uy if dy else 1 - uy
            for dz in (0, 1):
                wz = uz if dz else 1 - uz
                out += wx * wy * wz * _hash01(ix + dx, iy + dy, iz + dz, seed)
    return out


def plume(res=RES, seed: int = SEED) -> np.ndarray:
    """The density grid, indexed [z, y, x] (the .vol file's order), float32, peak 1."""
    nx, ny, nz = res
    # Voxel centres over [0, 1]^3.
    z, y, x = np.meshgrid((np.arange(nz) + 0.5) / nz, (np.arange(ny) + 0.5) / ny, (np.arange(nx) + 0.5) / nx,
                          indexing="ij")
    # The centre line meanders as the smoke rises (more the higher it is), and leans a little toward +x.
    sway = y ** 1.5
    cx = 0.5 + 0.06 * y + 0.07 * sway * np.sin(7.0 * y + 0.6)
    cz = 0.5 + 0.06 * sway * np.sin(5.0 * y + 2.1)
    r = np.hypot(x - cx, z - cz)
    radius = 0.07 + 0.29 * y ** 0.8
    # Turbulence: three octaves of value noise, advected upward (stretched along y) so the blobs are rising
    # wisps rather than round lumps.
    turb = np.zeros_like(x)
    amp, total = 1.0, 0.0
    for octave, freq in enumerate((5.0, 10.0, 20.0)):
        turb += amp * value_noise(x * freq, y * freq * 0.6, z * freq, seed + octave)
        total += amp
        amp *= 0.5
    turb /= total  # in [0, 1), mean about 0.5
    # The radius itself wobbles with the noise, so the edge is ragged, not a smooth cone.
    q = r / (radius * (0.75 + 0.5 * turb))
    core = np.exp(-2.5 * q * q)
    # Dense at the source, thinning as it rises and spreads; the source starts a little above the bottom face.
    rise = np.clip((y - 0.03) / 0.08, 0.0, 1.0) * (1.0 - 0.65 * y)
    density = core * rise * (0.2 + 2.0 * turb ** 2)
    # Fade to zero at the faces (the grid is clamped outside the box: this keeps the box invisible).
    edge = lambda t: np.clip(np.minimum(t, 1.0 - t) / 0.06, 0.0, 1.0)  # noqa: E731
    density *= edge(x) * edge(z) * np.clip((1.0 - y) / 0.15, 0.0, 1.0)
    # ... and exactly zero on the outer layer of voxels (the side faces, the top and the bottom).
    density[:, :, [0, -1]] = 0.0
    density[[0, -1]] = 0.0
    density[:, [0, -1]] = 0.0
    density /= density.max()
    return density.astype(np.float32)


def vol_bytes(grid: np.ndarray) -> bytes:
    """A one-channel grid indexed [z, y, x] as a Mitsuba .vol file over the unit cube."""
    nz, ny, nx = grid.shape
    header = b"VOL" + bytes([3]) + struct.pack("<5i6f", 1, nx, ny, nz, 1, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
    return header + np.ascontiguousarray(grid, dtype="<f4").tobytes()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-o", "--output", type=Path, default=Path(__file__).resolve().parent / "plume.vol",
                    help="where to write the grid (default: plume.vol beside this script)")
    a = ap.parse_args(argv)
    data = vol_bytes(plume())
    out = a.output
    out.parent.mkdir(parents=True, exist_ok=True)
    # Written beside its name and renamed over it, so a reader never sees half a file.
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    tmp.write_bytes(data)
    tmp.replace(out)
    print(f"wrote {out} ({len(data)} bytes, {RES[0]}x{RES[1]}x{RES[2]})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
