#include "neepp/math/spherical_rectangle.h"

#include <algorithm>
#include <cmath>

namespace neepp {

namespace {
constexpr double kTwoPi = 6.283185307179586476925;
}

SphericalRectangle::SphericalRectangle(const Vec3 &o, const Vec3 &corner, const Vec3 &ex, const Vec3 &ey, float len_x,
                                       float len_y)
    : corner_(corner), ex_(ex), ey_(ey) {
    const double dx = double(corner.x) - o.x, dy = double(corner.y) - o.y, dz = double(corner.z) - o.z;
    // The normal, as double: the height z0 of a nearby point must not lose what the float product would.
    const double nx = double(ex.y) * ey.z - double(ex.z) * ey.y, ny = double(ex.z) * ey.x - double(ex.x) * ey.z,
                 nz = double(ex.x) * ey.y - double(ex.y) * ey.x;
    x0_ = dx * ex.x + dy * ex.y + dz * ex.z;
    y0_ = dx * ey.x + dy * ey.y + dz * ey.z;
    z0_ = -std::abs(dx * nx + dy * ny + dz * nz);  // the normal's sign chosen to point toward o
    x1_ = x0_ + len_x;
    y1_ = y0_ + len_y;
    b0_ = b1_ = k_ = 0;
    if (!(z0_ < 0) || !(len_x > 0) || !(len_y > 0)) return;  // in the plane, or degenerate: nothing seen
    // The unit normals of the great circles through neighbouring corners (v00 v10, v10 v11, v11 v01,
    // v01 v00), written out, each with a zero component in this frame: n0 = (0, z0, -y0) r0,
    // n1 = (-z0, 0, x1) r1, n2 = (0, -z0, y1) r2, n3 = (z0, 0, -x0) r3. The internal angle at a corner v
    // between n_i and n_i+1 is acos(-<n_i, n_i+1>), here the argument of the complex number
    // -<n_i, n_i+1> + i |n_i x n_i+1| (with the common factor r_i r_i+1 dropped; |n_i x n_i+1| is
    // |z0| |v|): unlike acos, it keeps its precision where an angle nears 0 or pi (points just above the
    // plane), and two angles add as one product, so the four take two atan2 rather than four acos.
    const double z2 = z0_ * z0_, h = -z0_;
    struct Angle {
        double re, im;
    };
    auto corner_angle = [&](double x, double y, double minus_dot) { return Angle{minus_dot, h * std::sqrt(x * x + y * y + z2)}; };
    auto sum = [](Angle a, Angle b) {  // g_a + g_b, each in (0, pi)
        const double g = std::atan2(a.re * b.im + a.im * b.re, a.re * b.re - a.im * b.im);
        return g < 0 ? g + kTwoPi : g;
    };
    const Angle g0 = corner_angle(x1_, y0_, y0_ * x1_), g1 = corner_angle(x1_, y1_, -x1_ * y1_),
                g2 = corner_angle(x0_, y1_, x0_ * y1_), g3 = corner_angle(x0_, y0_, -x0_ * y0_);
    const double r0 = 1.0 / std::sqrt(z2 + y0_ * y0_), r2 = 1.0 / std::sqrt(z2 + y1_ * y1_);
    b0_ = -y0_ * r0;  // n0.z
    b1_ = y1_ * r2;   // n2.z
    k_ = kTwoPi - sum(g2, g3);
    solid_angle_ = std::max(0.0, sum(g0, g1) - k_);
}

Vec3 SphericalRectangle::sample(Vec2 u, float &s, float &t) const {
    // The x coordinate: the solid angle swept from the rectangle's x0 edge grows linearly with u.x.
    const double au = u.x * solid_angle_ + k_;
    const double fu = (std::cos(au) * b0_ - b1_) / std::sin(au);
    double cu = 1.0 / std::sqrt(fu * fu + b0_ * b0_);
    cu = std::clamp(fu > 0 ? cu : -cu, -1.0, 1.0);
    const double xu = std::clamp(-(cu * z0_) / std::sqrt(std::max(0.0, 1.0 - cu * cu)), x0_, x1_);
    // The y coordinate, uniform in the sine of the elevation seen along that column.
    const double d2 = xu * xu + z0_ * z0_, d = std::sqrt(d2);
    const double h0 = y0_ / std::sqrt(d2 + y0_ * y0_), h1 = y1_ / std::sqrt(d2 + y1_ * y1_);
    const double hv = h0 + u.y * (h1 - h0), hv2 = hv * hv;
    const double yv = hv2 < 1.0 - 1e-12 ? std::clamp(hv * d / std::sqrt(1.0 - hv2), y0_, y1_) : y1_;
    // From the corner: the point lies in the rectangle's plane to float precision, whatever o's distance.
    s = float((xu - x0_) / (x1_ - x0_));
    t = float((yv - y0_) / (y1_ - y0_));
    return corner_ + ex_ * float(xu - x0_) + ey_ * float(yv - y0_);
}

}  // namespace neepp
