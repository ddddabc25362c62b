"""Writes sdf_grid_reference.inc: Mitsuba 3's own intersections of rays with its `sdfgrid` shape, for the
grid and the to_world that test_sdf_grid.cpp builds: for each ray whether it hits, and where, the
distance, the geometric normal and the shading normal with `normals` set to `smooth` and to `analytic`.

The grid has fewer points along y than along x and z (6 x 5 x 6), so that an axis read in the wrong order
shows (x and z must match: Mitsuba 3.9 finds a voxel from its index with the z size where the x size
belongs, in SDFGrid::to_voxel_position, and misses the surface of grids whose x and z sizes differ; neepp
does not copy that), and holds a lumpy ellipsoid, so that no voxel's gradient vanishes (Mitsuba's smooth
normal is NaN where one of the eight voxels around the point has a zero gradient). to_world scales and
translates only: Mitsuba bounds a directly transformed grid's voxels by their transformed corners, which
a rotation breaks (it warns to use an instance instead).

Run with the Python that has the mitsuba package (scripts/test.sh installs it in .venv):
    .venv/bin/python tests/shapes/generate_sdf_grid_reference.py > tests/shapes/sdf_grid_reference.inc
"""
import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")

SIZE = (6, 5, 6)  # x, y, z
SCALE = (1.6, 1.2, 1.4)
TRANSLATE = (0.2, -0.3, 0.1)


def grid_values() -> np.ndarray:
    """The grid as Mitsuba's tensor wants it, [z, y, x, 1]."""
    nx, ny, nz = SIZE
    z, y, x = np.meshgrid(np.arange(nz) / (nz - 1), np.arange(ny) / (ny - 1), np.arange(nx) / (nx - 1), indexing="ij")
    q = np.stack([(x - 0.45) / 0.36, (y - 0.52) / 0.3, (z - 0.5) / 0.28], axis=-1)
    values = (np.linalg.norm(q, axis=-1) - 1) * 0.28 + 0.03 * np.sin(5 * x + 3 * y) * np.cos(4 * z)
    return values.astype(np.float32)[..., None]


def rays():
    """Rays from around the grid toward points near its middle, a few from inside it and a few that pass."""
    rng = np.random.RandomState(7)
    world_center = np.array(SCALE) * 0.5 + np.array(TRANSLATE)
    out = []
    for i in range(48):
        if i < 36:  # from outside, toward the shape
            d = rng.normal(size=3)
            o = world_center + 2.5 * d / np.linalg.norm(d)
            target = world_center + rng.uniform(-0.3, 0.3, size=3)
        elif i < 42:  # from inside
            o = world_center + rng.uniform(-0.1, 0.1, size=3)
            target = o + rng.normal(size=3)
        else:  # from outside, passing beside the grid
            o = world_center + np.array([3.0, rng.uniform(-2, 2), rng.uniform(-2, 2)])
            target = world_center + np.array([0.0, 1.8, 1.8]) * np.sign(rng.uniform(-1, 1, size=3))
        d = target - o
        out.append((o.astype(np.float32), (d / np.linalg.norm(d)).astype(np.float32)))
    return out


def f(x) -> str:
    return repr(float(np.float32(x))) + "f"


def vec(v) -> str:
    return "{" + ", ".join(f(c) for c in v) + "}"


def main():
    values = grid_values()
    print("// Reference values generated with Mitsuba %s (pip package, scalar_rgb variant) by" % mi.__version__)
    print("// tests/shapes/generate_sdf_grid_reference.py.")
    print(f"constexpr uint32_t kReferenceGridSize[3] = {{{SIZE[0]}, {SIZE[1]}, {SIZE[2]}}};")
    print(f"const Vec3 kReferenceScale{vec(SCALE)}, kReferenceTranslate{vec(TRANSLATE)};")
    print("// x fastest, then y, then z.")
    print("const float kReferenceGridValues[] = {")
    flat = values[..., 0].reshape(-1)
    for i in range(0, len(flat), 8):
        print("    " + ", ".join(f(v) for v in flat[i:i + 8]) + ",")
    print("};")
    scenes = {}
    for mode in ("smooth", "analytic"):
        scenes[mode] = mi.load_dict({"type": "scene", "grid": {
            "type": "sdfgrid", "grid": mi.TensorXf(values), "normals": mode,
            "to_world": mi.ScalarTransform4f().translate(list(TRANSLATE)).scale(list(SCALE))}})
    print("// origin, direction, hit, t, geometric normal, smooth shading normal, analytic shading normal.")
    print("const SdfRayReference kReferenceRays[] = {")
    for o, d in rays():
        ray = mi.Ray3f(mi.ScalarPoint3f(*o), mi.ScalarVector3f(*d))
        smooth, analytic = scenes["smooth"].ray_intersect(ray), scenes["analytic"].ray_intersect(ray)
        assert bool(smooth.is_valid()) == bool(analytic.is_valid())
        if not smooth.is_valid():
            print(f"    {{{vec(o)}, {vec(d)}, false, 0.f, {{}}, {{}}, {{}}}},")
            continue
        assert abs(smooth.t - analytic.t) < 1e-6
        print(f"    {{{vec(o)}, {vec(d)}, true, {f(smooth.t)}, {vec(smooth.n)}, {vec(smooth.sh_frame.n)}, "
              f"{vec(analytic.sh_frame.n)}}},")
    print("};")


if __name__ == "__main__":
    main()
