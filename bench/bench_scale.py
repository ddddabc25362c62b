#!/usr/bin/env python3
"""Scale benchmark (issue 42, 'Scale'): how neepp holds up as scenes grow, in three parts.

lights   A generated house of 4x4 rooms under one ceiling of --lights small emissive rectangles (10^4 by
         default, each a light of its own, radiances varied), walls up to the ceiling with one doorway per
         wall, the camera in a corner room: from most shading points most lights are behind walls. Every
         light sampler that scales (power, the light BVH, the spatial estimate, and the visibility-aware
         ones over them) at equal spp: load time, time to the first pass's tables (the map's build), render
         time, peak memory, the sampler's own statistics, relative variance from two seeds and efficiency
         1 / (relVar x CPU time) against the light BVH with plain NEE.
mesh     A generated height field of about --mesh-triangles triangles (binary PLY) under a sky: load time,
         peak memory and time to a first 1-spp image in neepp and in Mitsuba 3 (llvm_ad_rgb).
threads  samples/s with 1 and 2 threads on a scene (classroom when the shared scenes are there): how the
         render scales with cores.

    .venv/bin/python bench/bench_scale.py                       # all three, ~10 min on 2 cores
    .venv/bin/python bench/bench_scale.py --parts lights --lights 2500

Writes bench/out/scale/ (git-ignored): report.md, results.json and the generated scenes.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from neepp_tools import SCENES_DIR, machine, metrics, runner  # noqa: E402

ROOMS, ROOM, HEIGHT, DOOR = 4, 5.0, 3.0, 1.0  # rooms per side, room size and height, doorway width (m)

SAMPLERS = [  # (light_sampler, shadow_rays)
    ("bvh", "nee"), ("power", "nee"), ("spatial", "nee"),
    ("visibility-bvh", "neepp"), ("visibility", "neepp"), ("visibility-power", "neepp"),
]


def house_xml(n_lights: int, seed: int = 3) -> str:
    """The many-light house: n_lights rectangles on a square grid under the ceiling, facing down."""
    rng = np.random.default_rng(seed)
    side = int(round(np.sqrt(n_lights)))
    size = ROOMS * ROOM
    pitch = size / side
    half = 0.3 * pitch
    out = ['<scene version="3.0.0">', '<default name="resx" value="160"/>', '<default name="resy" value="90"/>',
           '<integrator type="path"><integer name="max_depth" value="5"/></integrator>',
           '<sensor type="perspective"><float name="fov" value="75"/>',
           f'<transform name="to_world"><lookat origin="0.6, 1.6, 0.6" target="{ROOM}, 1.2, {ROOM * 0.5}" up="0, 1, 0"/></transform>',
           '<sampler type="independent"><integer name="sample_count" value="16"/></sampler>',
           '<film type="hdrfilm"><integer name="width" value="$resx"/><integer name="height" value="$resy"/>'
           '<rfilter type="box"/></film></sensor>',
           '<bsdf type="diffuse" id="wall"><rgb name="reflectance" value="0.6, 0.6, 0.6"/></bsdf>']

    def box(x0, x1, y0, y1, z0, z1):
        c = ((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2)
        h = ((x1 - x0) / 2, (y1 - y0) / 2, (z1 - z0) / 2)
        out.append(f'<shape type="cube"><ref id="wall"/><transform name="to_world">'
                   f'<scale x="{h[0]:.6g}" y="{h[1]:.6g}" z="{h[2]:.6g}"/>'
                   f'<translate x="{c[0]:.6g}" y="{c[1]:.6g}" z="{c[2]:.6g}"/></transform></shape>')

    t = 0.05  # wall thickness
    box(0, size, -t, 0, 0, size)              # floor
    box(0, size, HEIGHT, HEIGHT + t, 0, size)  # ceiling
    for k in range(ROOMS + 1):                 # walls along z (at x = k ROOM) and along x, a door in each room's
        c = k * ROOM
        for r in range(ROOMS):
            a, b = r * ROOM, (r + 1) * ROOM
            d0, d1 = (a + b - DOOR) / 2, (a + b + DOOR) / 2
            spans = [(a, b)] if k in (0, ROOMS) else [(a, d0), (d1, b)]
            for s0, s1 in spans:
                box(c - t, c + t, 0, HEIGHT, s0, s1)
                box(s0, s1, 0, HEIGHT, c - t, c + t)
    radiance = rng.lognormal(0.0, 1.0, size=side * side) * 20.0
    for i in range(side):
        for j in range(side):
            x, z, L = (i + 0.5) * pitch, (j + 0.5) * pitch, radiance[i * side + j]
            out.append(f'<shape type="rectangle"><transform name="to_world"><scale x="{half:.6g}" y="{half:.6g}"/>'
                       f'<rotate x="1" angle="90"/><translate x="{x:.6g}" y="{HEIGHT - 0.01:.6g}" z="{z:.6g}"/>'
                       f'</transform><emitter type="area"><rgb name="radiance" value="{L:.5g}"/></emitter>'
                       f'<bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf></shape>')
    out.append('</scene>')
    return "\n".join(out)


def write_height_field(path: Path, triangles: int) -> int:
    """A rolling terrain as a binary little-endian PLY of about `triangles` triangles; returns the count."""
    n = int(np.sqrt(triangles / 2))
    xs = np.linspace(-10.0, 10.0, n + 1, dtype=np.float32)
    X, Z = np.meshgrid(xs, xs, indexing="ij")
    Y = (0.6 * np.sin(0.9 * X) * np.cos(0.7 * Z) + 0.15 * np.sin(4.1 * X + 2.3 * Z)).astype(np.float32)
    verts = np.stack([X, Y, Z], axis=-1).reshape(-1, 3)
    idx = np.arange((n + 1) * (n + 1), dtype=np.int32).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    face = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<i4", 3)])
    face["n"], face["i"] = 3, tris
    with open(path, "wb") as f:
        f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\nproperty float x\n"
                 f"property float y\nproperty float z\nelement face {len(tris)}\n"
                 "property list uchar int vertex_indices\nend_header\n").encode())
        f.write(verts.astype("<f4").tobytes())
        f.write(face.tobytes())
    return len(tris)


def terrain_xml(ply: Path) -> str:
    # The $ parameters are those Mitsuba's worker (neepp_tools.mitsuba_worker) sets.
    return f"""<scene version="3.0.0">
<default name="spp" value="1"/><default name="max_depth" value="3"/><default name="integrator" value="path"/>
<integrator type="$integrator"><integer name="max_depth" value="$max_depth"/></integrator>
<sensor type="perspective"><float name="fov" value="60"/>
<transform name="to_world"><lookat origin="0, 6, -16" target="0, 0, 0" up="0, 1, 0"/></transform>
<sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
<film type="hdrfilm"><integer name="width" value="320"/><integer name="height" value="180"/></film></sensor>
<emitter type="constant"><rgb name="radiance" value="1.0"/></emitter>
<shape type="ply"><string name="filename" value="{ply}"/>
<bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
</scene>
"""


def part_lights(a, out: Path, lines: list, results: dict):
    d = out / "house"
    d.mkdir(parents=True, exist_ok=True)
    xml = d / "scene.xml"
    xml.write_text(house_xml(a.lights))
    lines += [f"\n## {a.lights} lights: a house of {ROOMS}x{ROOMS} rooms, {a.res}, {a.spp} spp, max depth 5, "
              f"{a.threads} threads\n",
              "| sampler | shadow rays | load s | map build s | render s | CPU s | peak MB | tables | relVar | efficiency vs bvh |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    w, h = (int(x) for x in a.res.split("x"))
    runs = {}
    for sampler, policy in SAMPLERS:
        if a.samplers and sampler != "bvh" and sampler not in a.samplers.split(","):
            continue
        pair = [runner.run_neepp(xml, d / f"{sampler}_{k}.exr", spp=a.spp, resx=w, resy=h, seed=1 + 1000 * k,
                                 threads=a.threads, integrator_args={"light_sampler": sampler, "shadow_rays": policy},
                                 timeout=7200) for k in range(2)]
        runs[(sampler, policy)] = pair
    ref = np.mean([r.image for pair in runs.values() for r in pair], axis=0)
    rows = {}
    for (sampler, policy), pair in runs.items():
        st = pair[0].stats
        ist = st.get("integrator_statistics", {})
        cpu = sum(r.stats["render_cpu_time_s"] for r in pair) / 2
        rel_var = metrics.relative_variance(pair[0].image, pair[1].image, ref)
        rows[sampler] = {"shadow_rays": policy, "load_s": st["load_time_s"],
                         "map_build_s": ist.get("shadow_rays", {}).get("map", {}).get("build_time_s", 0.0),
                         "render_s": st["render_time_s"], "cpu_s": cpu, "peak_mb": st["peak_memory_mb"],
                         "light_sampler": ist.get("light_sampler", {}), "relVar": rel_var,
                         "efficiency": 1.0 / (rel_var * cpu)}
    base = rows["bvh"]["efficiency"]
    for sampler, r in rows.items():
        r["efficiency_vs_bvh"] = r["efficiency"] / base
        tables = r["light_sampler"].get("tables_built", "-")
        lines.append(f"| {sampler} | {r['shadow_rays']} | {r['load_s']:.2f} | {r['map_build_s']:.2f} | "
                     f"{r['render_s']:.2f} | {r['cpu_s']:.2f} | {r['peak_mb']:.0f} | {tables} | {r['relVar']:.4g} | "
                     f"{r['efficiency_vs_bvh']:.2f} |")
        print(lines[-1], flush=True)
    results["lights"] = {"lights": a.lights, "rows": rows}


def part_mesh(a, out: Path, lines: list, results: dict, variant: str):
    d = out / "terrain"
    d.mkdir(parents=True, exist_ok=True)
    ply = d / "terrain.ply"
    n = write_height_field(ply, a.mesh_triangles)
    xml = d / "scene.xml"
    xml.write_text(terrain_xml(ply.resolve()))
    ours = runner.run_neepp(xml, d / "neepp.exr", spp=1, threads=a.threads, timeout=3600)
    theirs = runner.run_mitsuba(xml, d / "mitsuba.exr", variant=variant, spp=1, max_depth=3, threads=a.threads,
                                timeout=3600)
    row = {"triangles": n, "ply_mb": ply.stat().st_size / 2**20,
           "neepp": {"load_s": ours.stats["load_time_s"], "peak_mb": ours.stats["peak_memory_mb"], "wall_s": ours.wall_s,
                     "mesh_bytes_per_triangle": ours.stats.get("mesh_memory_mb", float("nan")) * 2**20 / n},
           "mitsuba": {"load_s": theirs.stats.get("load_time_s"), "peak_mb": theirs.peak_rss_mb, "wall_s": theirs.wall_s}}
    results["mesh"] = row
    lines += [f"\n## A height field of {n} triangles ({row['ply_mb']:.0f} MB binary PLY), 320x180, 1 spp\n",
              "| renderer | load s | peak MB | wall s (process, to the written image) |", "|---|---|---|---|",
              f"| neepp | {row['neepp']['load_s']:.2f} | {row['neepp']['peak_mb']:.0f} | {row['neepp']['wall_s']:.2f} |",
              f"| Mitsuba 3 {variant} | {row['mitsuba']['load_s']:.2f} | {row['mitsuba']['peak_mb']:.0f} | "
              f"{row['mitsuba']['wall_s']:.2f} |",
              f"| ratio neepp / Mitsuba | {row['neepp']['load_s'] / row['mitsuba']['load_s']:.2f} | "
              f"{row['neepp']['peak_mb'] / row['mitsuba']['peak_mb']:.2f} | {row['neepp']['wall_s'] / row['mitsuba']['wall_s']:.2f} |",
              f"\nneepp's meshes hold {row['neepp']['mesh_bytes_per_triangle']:.1f} bytes a triangle (the stats' "
              "mesh_memory_mb: arrays Embree shares, the area table; Embree's BVH not counted)."]
    print("\n".join(lines[-7:]), flush=True)


def part_threads(a, out: Path, lines: list, results: dict):
    xml = SCENES_DIR / "classroom" / "scene.xml"
    name, res = "classroom", (320, 180)
    if not xml.exists():
        xml, name, res = REPO / "scenes" / "door-ajar" / "scene.xml", "door-ajar", (320, 180)
    rates = {}
    for threads in (1, 2, 1, 2):  # interleaved, best of two each: the machine is shared and noisy
        r = runner.run_neepp(xml, out / f"threads_{threads}.exr", spp=a.thread_spp, resx=res[0], resy=res[1],
                             seed=1, threads=threads, timeout=3600)
        rates[threads] = max(rates.get(threads, 0.0), r.stats["samples_per_s"])
    results["threads"] = {"scene": name, "samples_per_s": rates, "scaling": rates[2] / rates[1]}
    lines += [f"\n## Threads: {name} {res[0]}x{res[1]}, {a.thread_spp} spp, best of two interleaved runs\n",
              "| threads | samples/s |", "|---|---|", f"| 1 | {rates[1]:.4g} |", f"| 2 | {rates[2]:.4g} |",
              f"\n2 threads / 1 thread: {rates[2] / rates[1]:.2f}x"]
    print("\n".join(lines[-6:]), flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--parts", default="lights,mesh,threads")
    ap.add_argument("--lights", type=int, default=10000, help="emissive rectangles (a square number)")
    ap.add_argument("--samplers", default="", help="only these light samplers (comma-separated; bvh is always run)")
    ap.add_argument("--res", default="160x90")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--mesh-triangles", type=int, default=4_000_000)
    ap.add_argument("--thread-spp", type=int, default=8)
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "scale"))
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    lines = ["# Scale benchmark (bench/bench_scale.py)\n", f"machine: {machine.summary()}"]
    results: dict = {}
    parts = a.parts.split(",")
    if "lights" in parts:
        part_lights(a, out, lines, results)
    if "mesh" in parts:
        ok, why = runner.mitsuba_available("llvm_ad_rgb")
        part_mesh(a, out, lines, results, "llvm_ad_rgb" if ok else "scalar_rgb")
    if "threads" in parts:
        part_threads(a, out, lines, results)
    (out / "results.json").write_text(json.dumps(results, indent=2, default=str))
    (out / "report.md").write_text("\n".join(lines) + "\n")
    print(f"\nwrote {out / 'report.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
