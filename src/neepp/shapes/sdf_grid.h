// Mitsuba 3's `sdfgrid` shape in its own space: a signed distance function (positive outside) sampled at
// the corners of a grid that spans [0, 1]^3, interpolated trilinearly between them; the surface is where
// it is 0. As in Mitsuba (after Hansson-Söderlund, Evans and Akenine-Möller 2022, "Ray Tracing of Signed
// Distance Function Grids"), only the voxels whose corners do not all have one strict sign can hold
// surface; each is one primitive for Embree, bounded by the box of the surface's crossings of its edges
// (which holds all of the surface inside it: Hansson-Söderlund and Akenine-Möller 2023), and a ray meets
// the surface in a voxel at the first root of a cubic, the interpolant along the ray.
#pragma once
#include <cstdint>
#include <vector>
#include "neepp/math/bbox.h"

namespace neepp {

class SdfGrid {
public:
    // Mitsuba's `normals` option: `smooth` blends the normals of the eight voxels around the nearest grid
    // point (Hansson-Söderlund et al. 2022), continuous across voxels; `analytic` is the gradient of the
    // voxel's own interpolant, the geometric normal.
    enum class Normals { Smooth, Analytic };

    // values: nx * ny * nz, x fastest, then y, then z. Throws std::invalid_argument when a size is below 2,
    // the count is wrong, a value is not finite, or no voxel holds surface (Mitsuba refuses that too).
    SdfGrid(uint32_t nx, uint32_t ny, uint32_t nz, std::vector<float> values, Normals normals = Normals::Smooth);

    uint32_t size(int axis) const { return size_[axis]; }
    const std::vector<float> &values() const { return values_; }
    Normals normals() const { return normals_; }

    // The voxels that hold surface (Embree's primitives) and, for each, a box around its surface in the
    // grid's space, widened by a thousandth of a voxel so that a ray grazing it still reaches the voxel's
    // own test.
    size_t voxel_count() const { return voxels_.size(); }
    const BBox &surface_bounds(size_t voxel) const { return voxels_[voxel].bounds; }

    // The first point at which the ray o + t d (grid space, d of any length) meets the surface inside the
    // voxel, with t in [tmin, tmax]: true and its t, or false.
    bool intersect(size_t voxel, const Vec3 &o, const Vec3 &d, float tmin, float tmax, float &t) const;

    // The interpolated distance at p (grid space; outside [0, 1]^3, that of the nearest point of it).
    float value(const Vec3 &p) const;
    // The geometric normal's direction at p (not unit): the gradient of the interpolant of p's voxel.
    Vec3 gradient(const Vec3 &p) const;
    // The shading normal's direction at p (not unit), by the `normals` option.
    Vec3 shading_normal(const Vec3 &p) const;

private:
    struct Voxel {
        uint32_t x, y, z;  // its lowest corner
        BBox bounds;
    };
    float corner(int64_t x, int64_t y, int64_t z) const {
        return values_[(size_t(z) * size_[1] + size_t(y)) * size_[0] + size_t(x)];
    }
    // value() in grid-point units (g = p * (size - 1)).
    float value_at(const Vec3 &g) const;
    // The gradient of voxel v's interpolant at the grid-point position g (Mitsuba's voxel_grad: each
    // component the difference across the voxel at g's other two coordinates).
    Vec3 voxel_gradient(const Vec3 &g, int64_t vx, int64_t vy, int64_t vz) const;
    Vec3 smooth_normal(const Vec3 &g) const;

    uint32_t size_[3];
    std::vector<float> values_;
    Normals normals_;
    std::vector<Voxel> voxels_;
};

}  // namespace neepp
