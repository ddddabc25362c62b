#include "neepp/media/volume.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace neepp {

BBox unit_cube_bounds(const Transform &to_world) {
    BBox b;
    for (int k = 0; k < 8; ++k) b.expand(to_world.point(Vec3(float(k & 1), float(k >> 1 & 1), float(k >> 2 & 1))));
    return b;
}

std::string symmetric_matrix_problem(const SymmetricMatrix3 &s) {
    for (float v : s.channels())
        if (!std::isfinite(v)) return "holds " + std::to_string(v) + ": not a finite number";
    const std::array<double, 3> e = eigenvalues(s);
    // Rounding leaves a flat or a fibre-like matrix (an eigenvalue of 0) a little below 0 at worst.
    if (e[0] < -1e-4 * std::max(e[2], 0.0) || e[2] < 0)
        return "has an eigenvalue of " + std::to_string(e[0]) +
               ": it is not positive semi-definite, as an SGGX matrix S must be";
    return "";
}

ConstantVolume::ConstantVolume(const SymmetricMatrix3 &value, const Transform &to_world)
    : value_(value.xx, value.yy, value.zz), matrix_(value), channels_(6), bounds_(unit_cube_bounds(to_world)) {
    if (const std::string problem = symmetric_matrix_problem(value); !problem.empty())
        throw std::invalid_argument("the matrix (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz) " + problem);
    max_ = float(eigenvalues(value)[2]);
}

namespace {

// "(3, 0, 1)": a grid point, x fastest, then y, then z, so that the file's writer can find it.
std::string grid_point(const VolumeGrid &g, size_t point) {
    return "(" + std::to_string(point % g.size[0]) + ", " + std::to_string(point / g.size[0] % g.size[1]) + ", " +
           std::to_string(point / g.size[0] / g.size[1]) + ")";
}

}  // namespace

GridVolume::GridVolume(VolumeGrid grid, const GridVolumeOptions &options) : grid_(std::move(grid)), options_(options) {
    const uint32_t n = grid_.channels;
    if (n != 1 && n != 3 && n != 6)
        throw std::invalid_argument("the grid has " + std::to_string(n) +
                                    " channels; a gridvolume's value is grey (1 channel), RGB (3) or a symmetric "
                                    "matrix (6: an sggx phase function's S)");
    float data_max = 0;
    if (n == 6) {
        // Each point a matrix: its entries finite, off the diagonal of either sign, and the whole positive
        // semi-definite; its size is its largest eigenvalue.
        for (size_t point = 0; point * 6 < grid_.values.size(); ++point) {
            const SymmetricMatrix3 s = SymmetricMatrix3::from_channels(&grid_.values[point * 6]);
            if (const std::string problem = symmetric_matrix_problem(s); !problem.empty())
                throw std::invalid_argument("the matrix (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz) at grid point " +
                                            grid_point(grid_, point) + " " + problem);
            data_max = std::max(data_max, float(eigenvalues(s)[2]));
        }
    } else {
        for (size_t i = 0; i < grid_.values.size(); ++i) {
            const float v = grid_.values[i];
            if (std::isfinite(v) && v >= 0) continue;
            throw std::invalid_argument(
                "the value at grid point " + grid_point(grid_, i / n) +
                (n > 1 ? ", channel " + std::to_string(i % n) + "," : "") + " is " + std::to_string(v) +
                (std::isfinite(v) ? ": a gridvolume's values (densities, albedos, weights) are not negative" : ": not a finite number"));
        }
        data_max = *std::max_element(grid_.values.begin(), grid_.values.end());
    }
    uniform_ = true;
    for (size_t i = n; i < grid_.values.size() && uniform_; ++i) uniform_ = grid_.values[i] == grid_.values[i % n];
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

SymmetricMatrix3 GridVolume::texel_matrix(int64_t x, int64_t y, int64_t z) const {
    const uint32_t ix = uint32_t(wrap(x, grid_.size[0])), iy = uint32_t(wrap(y, grid_.size[1])), iz = uint32_t(wrap(z, grid_.size[2]));
    return SymmetricMatrix3::from_channels(&grid_.values[((size_t(iz) * grid_.size[1] + iy) * grid_.size[0] + ix) * 6]);
}

template <class Value, class Fetch> Value GridVolume::interpolate(const Vec3 &p, Fetch texel) const {
    const Vec3 u = to_local_.point(p);
    const float res[3] = {float(grid_.size[0]), float(grid_.size[1]), float(grid_.size[2])};
    if (options_.filter == GridVolumeOptions::Filter::Nearest)
        return texel(int64_t(std::floor(u.x * res[0])), int64_t(std::floor(u.y * res[1])), int64_t(std::floor(u.z * res[2])));
    // Texel centres at (i + 0.5) / res, as Dr.Jit's lookups: the eight around u, weighted trilinearly.
    const float gx = u.x * res[0] - 0.5f, gy = u.y * res[1] - 0.5f, gz = u.z * res[2] - 0.5f;
    const float fx = std::floor(gx), fy = std::floor(gy), fz = std::floor(gz);
    const float wx = gx - fx, wy = gy - fy, wz = gz - fz;
    const int64_t x = int64_t(fx), y = int64_t(fy), z = int64_t(fz);
    auto lerp3 = [](const Value &a, const Value &b, float t) { return a * (1.f - t) + b * t; };
    const Value c00 = lerp3(texel(x, y, z), texel(x + 1, y, z), wx), c10 = lerp3(texel(x, y + 1, z), texel(x + 1, y + 1, z), wx);
    const Value c01 = lerp3(texel(x, y, z + 1), texel(x + 1, y, z + 1), wx),
                c11 = lerp3(texel(x, y + 1, z + 1), texel(x + 1, y + 1, z + 1), wx);
    return lerp3(lerp3(c00, c10, wy), lerp3(c01, c11, wy), wz);
}

Color GridVolume::eval(const Vec3 &p) const {
    return interpolate<Color>(p, [this](int64_t x, int64_t y, int64_t z) { return texel(x, y, z); });
}

SymmetricMatrix3 GridVolume::eval_matrix(const Vec3 &p) const {
    if (grid_.channels != 6) throw std::logic_error("eval_matrix: the grid has " + std::to_string(grid_.channels) + " channels, not 6");
    return interpolate<SymmetricMatrix3>(p, [this](int64_t x, int64_t y, int64_t z) { return texel_matrix(x, y, z); });
}

}  // namespace neepp
