// The regular grid NEE++ keys its visibility map by: N×N×N voxels over the (slightly enlarged) scene
// bounds, followed by a small cube map of direction bins that stand in for the "voxels" of environment
// lights (a shadow ray to the sky has no end point, only a direction). A cell is an index in
// [0, cell_count()): voxels first (linear x + N·(y + N·z)), then the direction bins.
#pragma once
#include <algorithm>
#include <cstdint>
#include "neepp/math/bbox.h"
#include "neepp/math/vec.h"

namespace neepp {

class VoxelGrid {
public:
    // 6 cube faces × 4 × 4 bins: coarse enough that seeding fills every (voxel, bin) pair with a few
    // hundred rays per voxel, fine enough to tell a window's direction from the walls'.
    static constexpr int kDirectionBinsPerFaceSide = 4;
    static constexpr int kDirectionBins = 6 * kDirectionBinsPerFaceSide * kDirectionBinsPerFaceSide;
    static constexpr int kMaxResolution = 32;  // the map is 4 B × M(M+1)/2 for M cells: 2.1 GB at 32

    VoxelGrid() = default;
    // Covers scene_bounds enlarged by 1% of its diagonal on every side (so points sampled exactly on the
    // boundary, and ray-offset points just outside it, fall inside). Throws on N outside [1, 32] or
    // invalid bounds.
    VoxelGrid(const BBox &scene_bounds, int resolution);
    // A grid over exactly these bounds (used when reading a map file, which stores the enlarged bounds).
    static VoxelGrid with_exact_bounds(const BBox &bounds, int resolution);

    int resolution() const { return n_; }
    const BBox &bounds() const { return bounds_; }
    uint32_t voxel_count() const { return uint32_t(n_) * n_ * n_; }
    uint32_t cell_count() const { return voxel_count() + kDirectionBins; }
    bool is_direction_cell(uint32_t cell) const { return cell >= voxel_count(); }

    // The voxel holding p; points outside the grid are clamped to the nearest boundary voxel (NaNs map to 0).
    // Inline: every NEE++ shadow query and visibility-aware light choice asks it.
    uint32_t voxel_of(const Vec3 &p) const {
        int x = axis_index(p.x, bounds_.lo.x, inv_cell_size_.x);
        int y = axis_index(p.y, bounds_.lo.y, inv_cell_size_.y);
        int z = axis_index(p.z, bounds_.lo.z, inv_cell_size_.z);
        return uint32_t(x + n_ * (y + n_ * z));
    }
    // The direction-bin cell of a (not necessarily unit) direction.
    uint32_t cell_of_direction(const Vec3 &d) const;
    // The cell of a shadow ray's far end: the voxel of `to`, or, toward an infinite light (no end point),
    // the direction bin of d.
    uint32_t cell_of_end(const Vec3 &to, const Vec3 &d, bool to_infinity) const {
        return to_infinity ? cell_of_direction(d) : voxel_of(to);
    }
    // Integer coordinates of a voxel cell.
    void voxel_coords(uint32_t cell, int &x, int &y, int &z) const;
    // A direction uniformly distributed over the cube-map bin's face patch (not uniform in solid angle;
    // seeding only needs directions spread across the bin), unit length.
    Vec3 direction_in_bin(uint32_t cell, Vec2 u) const;

private:
    int axis_index(float v, float lo, float inv) const {
        const float f = (v - lo) * inv;
        if (!(f >= 0.f)) return 0;  // written so that NaN lands on 0: !(f >= 0) is true for NaN
        return f >= float(n_) ? n_ - 1 : std::min(int(f), n_ - 1);
    }

    int n_ = 0;
    BBox bounds_;
    Vec3 inv_cell_size_;
};

}  // namespace neepp
