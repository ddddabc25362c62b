#include "neepp/visibility/voxel_grid.h"

#include <stdexcept>
#include <string>

namespace neepp {

namespace {
void check_resolution(int n) {
    if (n < 1 || n > VoxelGrid::kMaxResolution)
        throw std::invalid_argument("visibility grid: voxels must be in [1, " + std::to_string(VoxelGrid::kMaxResolution) +
                                    "], got " + std::to_string(n));
}
}  // namespace

VoxelGrid::VoxelGrid(const BBox &scene_bounds, int resolution) {
    check_resolution(resolution);
    if (!scene_bounds.valid()) throw std::invalid_argument("visibility grid: invalid scene bounds");
    // Enlarge by 1% of the diagonal (and a floor for degenerate, flat scenes) so every dimension has a
    // nonzero extent and offset ray origins stay inside.
    float margin = std::max(0.01f * norm(scene_bounds.extent()), 1e-4f);
    BBox b;
    b.lo = scene_bounds.lo - Vec3(margin);
    b.hi = scene_bounds.hi + Vec3(margin);
    *this = with_exact_bounds(b, resolution);
}

VoxelGrid VoxelGrid::with_exact_bounds(const BBox &bounds, int resolution) {
    check_resolution(resolution);
    Vec3 e = bounds.extent();
    if (!bounds.valid() || !(e.x > 0 && e.y > 0 && e.z > 0) || !is_finite(e))
        throw std::invalid_argument("visibility grid: bounds must have a positive finite extent");
    VoxelGrid g;
    g.n_ = resolution;
    g.bounds_ = bounds;
    g.inv_cell_size_ = Vec3(float(resolution)) / e;
    return g;
}

void VoxelGrid::voxel_coords(uint32_t cell, int &x, int &y, int &z) const {
    x = int(cell % uint32_t(n_));
    y = int((cell / uint32_t(n_)) % uint32_t(n_));
    z = int(cell / (uint32_t(n_) * uint32_t(n_)));
}

uint32_t VoxelGrid::cell_of_direction(const Vec3 &d) const {
    constexpr int S = kDirectionBinsPerFaceSide;
    float ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    int face;
    float u, v, m;
    // Cube-map face = dominant axis and its sign; (u, v) = the other two coordinates over the dominant one.
    if (ax >= ay && ax >= az) { face = d.x >= 0 ? 0 : 1; m = ax; u = d.y; v = d.z; }
    else if (ay >= az) { face = d.y >= 0 ? 2 : 3; m = ay; u = d.x; v = d.z; }
    else { face = d.z >= 0 ? 4 : 5; m = az; u = d.x; v = d.y; }
    if (!(m > 0)) return voxel_count();  // zero or NaN direction: any bin, the query is traced anyway
    auto bin = [&](float t) { return std::clamp(int((t / m * 0.5f + 0.5f) * S), 0, S - 1); };
    return voxel_count() + uint32_t(face * S * S + bin(u) * S + bin(v));
}

Vec3 VoxelGrid::direction_in_bin(uint32_t cell, Vec2 r) const {
    constexpr int S = kDirectionBinsPerFaceSide;
    int local = int(cell - voxel_count());
    int face = local / (S * S), bu = (local / S) % S, bv = local % S;
    float u = ((float(bu) + r.x) / S) * 2.f - 1.f, v = ((float(bv) + r.y) / S) * 2.f - 1.f;
    float s = (face % 2 == 0) ? 1.f : -1.f;
    Vec3 d;
    switch (face / 2) {
        case 0: d = Vec3(s, u, v); break;
        case 1: d = Vec3(u, s, v); break;
        default: d = Vec3(u, v, s); break;
    }
    return normalize(d);
}

}  // namespace neepp
