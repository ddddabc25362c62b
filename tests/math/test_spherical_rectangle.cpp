// The spherical rectangle (math/spherical_rectangle.h): its solid angle against the closed form for a
// point above a corner and, by superposition, anywhere above the plane; its samples on the rectangle and
// uniform in solid angle (a histogram of the rectangle's own coordinates weighted by the solid-angle
// Jacobian); points in the plane see nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "neepp/math/spherical_rectangle.h"
#include "neepp/sampling/rng.h"

namespace neepp {
namespace {

// Solid angle of the rectangle [0, a] x [0, b] seen from height h above its corner (0, 0).
double corner_solid_angle(double a, double b, double h) { return std::atan(a * b / (h * std::sqrt(h * h + a * a + b * b))); }

// Of [x0, x1] x [y0, y1] seen from (px, py, h), by signed superposition of corner rectangles.
double solid_angle_closed_form(double x0, double x1, double y0, double y1, double px, double py, double h) {
    auto signed_corner = [&](double x, double y) {
        const double a = x - px, b = y - py;
        return (a < 0) == (b < 0) ? corner_solid_angle(std::abs(a), std::abs(b), h)
                                  : -corner_solid_angle(std::abs(a), std::abs(b), h);
    };
    return signed_corner(x1, y1) - signed_corner(x0, y1) - signed_corner(x1, y0) + signed_corner(x0, y0);
}

TEST(SphericalRectangle, SolidAngleMatchesClosedForm) {
    // The rectangle [0, 2] x [0, 0.5] in the plane z = 0, seen from above and below, near and far, over it
    // and beside it; its frame rotated in space changes nothing.
    const Vec3 ex = normalize(Vec3(1.f, 2.f, 0.5f)), ey = normalize(cross(Vec3(0.3f, -0.1f, 1.f), ex));
    const Vec3 ez = cross(ex, ey), corner(0.3f, -1.f, 2.f);
    const float a = 2.f, b = 0.5f;
    struct Where {
        double px, py, h;
    };
    for (const Where w : {Where{1, 0.25, 0.01}, Where{1, 0.25, 1}, Where{-3, 2, 0.5}, Where{0.5, 0.1, -2},
                          Where{10, -7, 3}, Where{1, 0.25, 300}, Where{2.5, 0.3, 0.002}}) {
        const Vec3 o = corner + ex * float(w.px) + ey * float(w.py) + ez * float(w.h);
        const SphericalRectangle rect(o, corner, ex, ey, a, b);
        // Where o is, after rounding (0.002 above the plane, its height's rounding alone moves the solid
        // angle by 2e-5).
        auto along = [&](const Vec3 &axis) {
            return (double(o.x) - corner.x) * axis.x + (double(o.y) - corner.y) * axis.y + (double(o.z) - corner.z) * axis.z;
        };
        const double expected = solid_angle_closed_form(0, a, 0, b, along(ex), along(ey), std::abs(along(ez)));
        EXPECT_NEAR(rect.solid_angle(), expected, 2e-5 * expected + 1e-9) << w.px << " " << w.py << " " << w.h;
    }
    // In the plane: nothing.
    EXPECT_EQ(SphericalRectangle(Vec3(3.f, 0.2f, 0.f), Vec3(0.f), Vec3(1, 0, 0), Vec3(0, 1, 0), a, b).solid_angle(), 0.0);
}

// The density of the rectangle's points that uniform sampling in solid angle induces is
// cos / (dist² solid_angle) per unit area: binned over the rectangle's (s, t), each cell's expected count
// is that integrated over the cell.
TEST(SphericalRectangle, SamplesAreUniformInSolidAngle) {
    const Vec3 ex(1, 0, 0), ey(0, 1, 0), corner(0, 0, 0);
    const float a = 2.f, b = 1.f;
    for (const Vec3 o : {Vec3(0.3f, 0.2f, 0.15f), Vec3(3.f, -1.f, 0.4f), Vec3(1.f, 0.5f, -2.f)}) {
        const SphericalRectangle rect(o, corner, ex, ey, a, b);
        const double omega = rect.solid_angle();
        constexpr int kBins = 8, kN = 200000;
        std::vector<double> counts(kBins * kBins, 0.0);
        PCG32 rng(3, 5);
        for (int i = 0; i < kN; ++i) {
            float s, t;
            const Vec3 p = rect.sample(rng.next_2d(), s, t);
            ASSERT_GE(s, 0.f);
            ASSERT_LE(s, 1.f);
            ASSERT_GE(t, 0.f);
            ASSERT_LE(t, 1.f);
            ASSERT_NEAR(p.x, s * a, 1e-5f);
            ASSERT_NEAR(p.y, t * b, 1e-5f);
            ASSERT_EQ(p.z, 0.f);
            counts[std::min(kBins - 1, int(s * kBins)) * kBins + std::min(kBins - 1, int(t * kBins))] += 1;
        }
        double chi2 = 0;
        const double h = std::abs(o.z);
        for (int i = 0; i < kBins; ++i)
            for (int j = 0; j < kBins; ++j) {
                // The cell's solid angle, by the closed form: the expected share of the samples.
                const double share = solid_angle_closed_form(a * i / kBins, a * (i + 1) / kBins, b * j / kBins,
                                                             b * (j + 1) / kBins, o.x, o.y, h) / omega;
                const double expected = share * kN;
                chi2 += (counts[i * kBins + j] - expected) * (counts[i * kBins + j] - expected) / expected;
            }
        // 63 degrees of freedom: the 1e-6 quantile is near 130.
        EXPECT_LT(chi2, 130.0) << "from " << o.x << "," << o.y << "," << o.z;
    }
}

}  // namespace
}  // namespace neepp
