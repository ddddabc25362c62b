#include "neepp/shapes/sdf_grid.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace neepp {

namespace {

// A polynomial in s, lowest coefficient first.
template <size_t N> using Poly = std::array<double, N>;

// a + (b - a) w for polynomials a and b and the weight w = w0 + w1 s: one degree more.
template <size_t N> Poly<N + 1> lerp(const Poly<N> &a, const Poly<N> &b, double w0, double w1) {
    Poly<N + 1> r{};
    for (size_t i = 0; i < N; ++i) {
        const double diff = b[i] - a[i];
        r[i] += a[i] + diff * w0;
        r[i + 1] += diff * w1;
    }
    return r;
}

// The roots of the cubic's derivative inside (0, length), in increasing order: where it turns.
int turning_points(const Poly<4> &f, double length, double out[2]) {
    const double a = 3 * f[3], b = 2 * f[2], c = f[1];
    double r[2];
    int n = 0;
    if (a == 0) {
        if (b != 0) r[n++] = -c / b;
    } else if (const double disc = b * b - 4 * a * c; disc >= 0) {
        // The form that loses no precision to cancellation (Numerical Recipes 5.6).
        const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
        r[n++] = q / a;
        if (q != 0) r[n++] = c / q;
    }
    if (n == 2 && r[1] < r[0]) std::swap(r[0], r[1]);
    int kept = 0;
    for (int i = 0; i < n; ++i)
        if (r[i] > 0 && r[i] < length) out[kept++] = r[i];
    return kept;
}

// Grid points per axis along which an index is read: the floor of g, kept inside [0, last] (a NaN reads 0).
int64_t cell_index(float g, int64_t last) {
    if (!(g > 0)) return 0;
    return std::min<int64_t>(int64_t(g), last);
}

Vec3 normalized_or_zero(const Vec3 &v) {
    const float len = norm(v);
    return len > 0 ? v / len : Vec3(0.f);
}

}  // namespace

SdfGrid::SdfGrid(uint32_t nx, uint32_t ny, uint32_t nz, std::vector<float> values, Normals normals)
    : size_{nx, ny, nz}, values_(std::move(values)), normals_(normals) {
    if (nx < 2 || ny < 2 || nz < 2)
        throw std::invalid_argument("an SDF grid needs at least 2 points along each axis, not " + std::to_string(nx) +
                                    " x " + std::to_string(ny) + " x " + std::to_string(nz));
    if (values_.size() != size_t(nx) * ny * nz)
        throw std::invalid_argument("an SDF grid of " + std::to_string(nx) + " x " + std::to_string(ny) + " x " +
                                    std::to_string(nz) + " points needs as many values, not " + std::to_string(values_.size()));
    for (size_t i = 0; i < values_.size(); ++i)
        if (!std::isfinite(values_[i]))
            throw std::invalid_argument("the SDF value at grid point (" + std::to_string(i % nx) + ", " +
                                        std::to_string(i / nx % ny) + ", " + std::to_string(i / nx / ny) +
                                        ") is not finite (" + std::to_string(values_[i]) + ")");
    const Vec3 cell(1.f / float(nx - 1), 1.f / float(ny - 1), 1.f / float(nz - 1));
    constexpr float kWiden = 1e-3f;
    for (uint32_t z = 0; z + 1 < nz; ++z)
        for (uint32_t y = 0; y + 1 < ny; ++y)
            for (uint32_t x = 0; x + 1 < nx; ++x) {
                // Corner k is at (k & 1, k >> 1 & 1, k >> 2 & 1) in the voxel.
                float f[8];
                bool all_positive = true, all_negative = true;
                for (int k = 0; k < 8; ++k) {
                    f[k] = corner(x + (k & 1), y + (k >> 1 & 1), z + (k >> 2 & 1));
                    all_positive &= f[k] > 0;
                    all_negative &= f[k] < 0;
                }
                if (all_positive || all_negative) continue;
                // The surface's points on the voxel's edges: its corners at 0 and the edges' sign changes.
                BBox local;
                for (int k = 0; k < 8; ++k) {
                    const Vec3 pk(float(k & 1), float(k >> 1 & 1), float(k >> 2 & 1));
                    if (f[k] == 0) local.expand(pk);
                    for (int axis = 0; axis < 3; ++axis) {
                        const int k2 = k | (1 << axis);
                        if (k2 == k || f[k] == 0 || f[k2] == 0 || (f[k] < 0) == (f[k2] < 0)) continue;
                        Vec3 crossing = pk;
                        crossing[axis] = std::clamp(f[k] / (f[k] - f[k2]), 0.f, 1.f);
                        local.expand(crossing);
                    }
                }
                const Vec3 at{float(x), float(y), float(z)};
                voxels_.push_back({x, y, z, {(at + local.lo - Vec3(kWiden)) * cell, (at + local.hi + Vec3(kWiden)) * cell}});
            }
    if (voxels_.empty())
        throw std::invalid_argument("the SDF grid holds no surface: every voxel's corners are all positive or all "
                                    "negative (Mitsuba refuses such a grid too)");
}

float SdfGrid::value_at(const Vec3 &g) const {
    int64_t i[3];
    float w[3];
    for (int a = 0; a < 3; ++a) {
        const float last = float(size_[a] - 1);
        const float x = g[a] > 0 ? std::min(g[a], last) : 0.f;
        i[a] = cell_index(x, size_[a] - 2);
        w[a] = x - float(i[a]);
    }
    float r = 0;
    for (int k = 0; k < 8; ++k) {
        const int bx = k & 1, by = k >> 1 & 1, bz = k >> 2 & 1;
        const float weight = (bx ? w[0] : 1 - w[0]) * (by ? w[1] : 1 - w[1]) * (bz ? w[2] : 1 - w[2]);
        r += weight * corner(i[0] + bx, i[1] + by, i[2] + bz);
    }
    return r;
}

float SdfGrid::value(const Vec3 &p) const {
    return value_at(p * Vec3(float(size_[0] - 1), float(size_[1] - 1), float(size_[2] - 1)));
}

Vec3 SdfGrid::voxel_gradient(const Vec3 &g, int64_t vx, int64_t vy, int64_t vz) const {
    const int64_t v[3] = {vx, vy, vz};
    Vec3 r;
    for (int a = 0; a < 3; ++a) {
        Vec3 lo = g, hi = g;
        lo[a] = float(v[a]);
        hi[a] = float(v[a] + 1);
        r[a] = (value_at(hi) - value_at(lo)) * float(size_[a] - 1);
    }
    return r;
}

Vec3 SdfGrid::gradient(const Vec3 &p) const {
    const Vec3 g = p * Vec3(float(size_[0] - 1), float(size_[1] - 1), float(size_[2] - 1));
    return voxel_gradient(g, cell_index(g.x, size_[0] - 2), cell_index(g.y, size_[1] - 2), cell_index(g.z, size_[2] - 2));
}

// Hansson-Söderlund et al. 2022, as Mitsuba computes it: the unit gradients of the eight voxels that share
// the grid point nearest to g, each at g, weighted trilinearly by g's place in the cube between their
// centres. A voxel before the grid's start (a negative index) has none and its side's weight is moved to
// the other; one past its end reads the grid clamped, as Mitsuba's texture lookups do.
Vec3 SdfGrid::smooth_normal(const Vec3 &g) const {
    int64_t c[3];
    for (int a = 0; a < 3; ++a) c[a] = g[a] > 0 ? int64_t(std::round(std::min(g[a], float(size_[a])))) : 0;
    Vec3 n[8];
    bool valid[8];
    for (int k = 0; k < 8; ++k) {
        const int64_t vx = c[0] - 1 + (k & 1), vy = c[1] - 1 + (k >> 1 & 1), vz = c[2] - 1 + (k >> 2 & 1);
        valid[k] = vx >= 0 && vy >= 0 && vz >= 0;
        n[k] = valid[k] ? normalized_or_zero(voxel_gradient(g, vx, vy, vz)) : Vec3(0.f);
    }
    float w[3];
    for (int a = 0; a < 3; ++a) {
        w[a] = g[a] - float(c[a]) + 0.5f;
        bool lower_valid = false, upper_valid = false;
        for (int k = 0; k < 8; ++k) (k >> a & 1 ? upper_valid : lower_valid) |= valid[k];
        if (!lower_valid) w[a] = 1;
        if (!upper_valid) w[a] = 0;
    }
    Vec3 r(0.f);
    for (int k = 0; k < 8; ++k) {
        const float weight = (k & 1 ? w[0] : 1 - w[0]) * (k >> 1 & 1 ? w[1] : 1 - w[1]) * (k >> 2 & 1 ? w[2] : 1 - w[2]);
        r += n[k] * weight;
    }
    return r;
}

Vec3 SdfGrid::shading_normal(const Vec3 &p) const {
    if (normals_ == Normals::Analytic) return gradient(p);
    return smooth_normal(p * Vec3(float(size_[0] - 1), float(size_[1] - 1), float(size_[2] - 1)));
}

bool SdfGrid::intersect(size_t voxel, const Vec3 &o, const Vec3 &d, float tmin, float tmax, float &t) const {
    const Voxel &v = voxels_[voxel];
    const double at[3] = {double(v.x), double(v.y), double(v.z)};
    // The ray in the voxel's own coordinates, [0, 1]^3 (t unchanged), clipped to it and to [tmin, tmax].
    double q[3], e[3], t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; ++a) {
        const double cells = double(size_[a] - 1);
        q[a] = double(o[a]) * cells - at[a];
        e[a] = double(d[a]) * cells;
        if (e[a] == 0) {
            if (!(q[a] >= 0 && q[a] <= 1)) return false;
            continue;
        }
        double ta = -q[a] / e[a], tb = (1 - q[a]) / e[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (!(t0 < t1)) return false;
    // The interpolant along the ray, s = t - t0 from the entry point c: lerps along x, then y, then z,
    // each weight linear in s, make it a cubic.
    double c[3];
    for (int a = 0; a < 3; ++a) c[a] = q[a] + e[a] * t0;
    Poly<2> fx[4];  // the edges along x, by (y, z) corner
    for (int yz = 0; yz < 4; ++yz) {
        const int64_t y = v.y + (yz & 1), z = v.z + (yz >> 1);
        fx[yz] = lerp<1>({double(corner(v.x, y, z))}, {double(corner(v.x + 1, y, z))}, c[0], e[0]);
    }
    const Poly<3> fy0 = lerp<2>(fx[0], fx[1], c[1], e[1]), fy1 = lerp<2>(fx[2], fx[3], c[1], e[1]);
    const Poly<4> f = lerp<3>(fy0, fy1, c[2], e[2]);
    auto f_at = [&](double s) { return ((f[3] * s + f[2]) * s + f[1]) * s + f[0]; };
    auto df_at = [&](double s) { return (3 * f[3] * s + 2 * f[2]) * s + f[1]; };

    // The cubic is monotonic between its turning points: the first piece whose ends differ in sign (or
    // that ends at 0) holds the first root, found by Newton's steps kept inside the piece by bisection.
    const double length = t1 - t0;
    double ends[3];
    int n = turning_points(f, length, ends);
    ends[n++] = length;
    double a = 0, fa = f_at(0);
    if (fa == 0) {
        t = float(t0);
        return true;
    }
    for (int i = 0; i < n; ++i) {
        const double b = ends[i], fb = f_at(b);
        if (fb != 0 && (fa < 0) == (fb < 0)) {
            a = b, fa = fb;
            continue;
        }
        double lo = a, hi = b, s = fb == 0 ? b : 0.5 * (a + b);
        const bool negative_before = fa < 0;
        const double tolerance = 1e-10 * length;
        for (int iter = 0; iter < 64 && fb != 0; ++iter) {
            const double fs = f_at(s);
            if (fs == 0) break;
            ((fs < 0) == negative_before ? lo : hi) = s;
            double next = s - fs / df_at(s);
            if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // also a flat derivative's inf or NaN
            const bool converged = std::abs(next - s) <= tolerance || hi - lo <= tolerance;
            s = next;
            if (converged) break;
        }
        t = float(t0 + s);
        return true;
    }
    return false;
}

}  // namespace neepp
