#include "neepp/media/volume.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace neepp {

BBox unit_cube_bounds(const Transform &to_world) {
    BBox b;
    for (int k = 0; k < 8; ++k) b.expand(to_world.point(Vec3(float(k & 1), float(k >> 1 & 1), float(k >> 2 & 1))));
    return b;
}

GridVolume::GridVolume(VolumeGrid grid, const GridVolumeOptions &options) : grid_(std::move(grid)), options_(options) {
    if (grid_.channels != 1 && grid_.channels != 3)
        throw std::invalid_argument("the grid has " + std::to_string(grid_.channels) +
                                    " channels; a gridvolume's value is grey (1 channel) or RGB (3)");
    // Where a bad value is, so that the file's writer can find it: x fastest, then y, then z.
    for (size_t i = 0; i < grid_.values.size(); ++i) {
        const float v = grid_.values[i];
        if (std::isfinite(v) && v >= 0) continue;
        const size_t point = i / grid_.channels;
        throw std::invalid_argument(
            "the value at grid point (" + std::to_string(point % grid_.size[0]) + ", " +
            std::to_string(point / grid_.size[0] % grid_.size[1]) + ", " + std::to_string(point / grid_.size[0] / grid_.size[1]) +
            ")" + (grid_.channels > 1 ? ", channel " + std::to_string(i % grid_.channels) + "," : "") + " is " +
            std::to_string(v) +
            (std::isfinite(v) ? ": a gridvolume's values (densities, albedos, weights) are not negative" : ": not a finite number"));
    }
    const float data_max = *std::max_element(grid_.values.begin(), grid_.values.end());
    // max() bounds the data: a heterogeneous medium draws its free flights against it, and a bound below
    // the data would bias every image (Mitsuba renders such a scene without a word).
    if (options.max_value > 0 && options.max_value < data_max)
        throw std::invalid_argument("max_value " + std::to_string(options.max_value) + " is below the grid's largest value " +
                                    std::to_string(data_max) + ": it must bound the data");
    max_ = options.max_value > 0 ? options.max_value : data_max;
    // to_local maps world points to the unit cube: through to_world's inverse, then, with use_grid_bbox,
    // from the file's bounds.
    Transform to_world = options.to_world;
    if (options.use_grid_bbox) {
        const Vec3 lo = grid_.bounds.lo, extent = grid_.bounds.hi - grid_.bounds.lo;
        const bool finite = std::isfinite(lo.x) && std::isfinite(lo.y) && std::isfinite(lo.z) && std::isfinite(extent.x) &&
                            std::isfinite(extent.y) && std::isfinite(extent.z);
        if (!finite || !(extent.x > 0 && extent.y > 0 && extent.z > 0))
            throw std::invalid_argument("use_grid_bbox: the grid's stored bounds are not a finite box of some volume");
        to_world = to_world * Transform::translate(lo) * Transform::scale(extent);
    }
    to_local_ = Transform(to_world.inverse_matrix, to_world.matrix);
    bounds_ = unit_cube_bounds(to_world);
}

int64_t GridVolume::wrap(int64_t i, uint32_t n) const {
    const int64_t m = int64_t(n);
    switch (options_.wrap) {
    case GridVolumeOptions::Wrap::Clamp: return std::clamp<int64_t>(i, 0, m - 1);
    case GridVolumeOptions::Wrap::Repeat: return ((i % m) + m) % m;
    case GridVolumeOptions::Wrap::Mirror: {
        const int64_t period = ((i % (2 * m)) + 2 * m) % (2 * m);
        return period < m ? period : 2 * m - 1 - period;
    }
    }
    return 0;
}

Color GridVolume::texel(int64_t x, int64_t y, int64_t z) const {
    const uint32_t ix = uint32_t(wrap(x, grid_.size[0])), iy = uint32_t(wrap(y, grid_.size[1])), iz = uint32_t(wrap(z, grid_.size[2]));
    if (grid_.channels == 1) return Color(grid_.at(ix, iy, iz));
    return Color(grid_.at(ix, iy, iz, 0), grid_.at(ix, iy, iz, 1), grid_.at(ix, iy, iz, 2));
}

Color GridVolume::eval(const Vec3 &p) const {
    const Vec3 u = to_local_.point(p);
    const float res[3] = {float(grid_.size[0]), float(grid_.size[1]), float(grid_.size[2])};
    if (options_.filter == GridVolumeOptions::Filter::Nearest)
        return texel(int64_t(std::floor(u.x * res[0])), int64_t(std::floor(u.y * res[1])), int64_t(std::floor(u.z * res[2])));
    // Texel centres at (i + 0.5) / res, as Dr.Jit's lookups: the eight around u, weighted trilinearly.
    const float gx = u.x * res[0] - 0.5f, gy = u.y * res[1] - 0.5f, gz = u.z * res[2] - 0.5f;
    const float fx = std::floor(gx), fy = std::floor(gy), fz = std::floor(gz);
    const float wx = gx - fx, wy = gy - fy, wz = gz - fz;
    const int64_t x = int64_t(fx), y = int64_t(fy), z = int64_t(fz);
    auto lerp3 = [](const Color &a, const Color &b, float t) { return a * (1.f - t) + b * t; };
    const Color c00 = lerp3(texel(x, y, z), texel(x + 1, y, z), wx), c10 = lerp3(texel(x, y + 1, z), texel(x + 1, y + 1, z), wx);
    const Color c01 = lerp3(texel(x, y, z + 1), texel(x + 1, y, z + 1), wx),
                c11 = lerp3(texel(x, y + 1, z + 1), texel(x + 1, y + 1, z + 1), wx);
    return lerp3(lerp3(c00, c10, wy), lerp3(c01, c11, wy), wz);
}

}  // namespace neepp
