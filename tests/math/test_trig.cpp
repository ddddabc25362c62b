// The polynomial sine and cosine against double precision over their whole range, and the concentric
// disk built on them against its angle form.
#include <gtest/gtest.h>

#include <cmath>

#include "neepp/math/trig.h"
#include "neepp/math/warp.h"

namespace neepp::test {
namespace {

TEST(Trig, SinCosQuarterWithinAnUlpOrTwo) {
    double worst_sin = 0, worst_cos = 0;
    constexpr int kSteps = 1 << 20;
    for (int i = 0; i <= kSteps; ++i) {
        const float x = float(-M_PI / 4 + M_PI / 2 * double(i) / kSteps);
        const SinCos t = sincos_quarter(x);
        // Error in units of the float spacing at the exact value (at least the spacing at 2^-24 · x's size,
        // where sin(x) ~ x is tiny).
        const double s = std::sin(double(x)), c = std::cos(double(x));
        worst_sin = std::max(worst_sin, std::abs(t.sin - s) / std::max(std::abs(s), 1e-30) * 0x1p24);
        worst_cos = std::max(worst_cos, std::abs(t.cos - c) / c * 0x1p24);
    }
    EXPECT_LE(worst_sin, 2.0);  // relative error in units of 2^-24
    EXPECT_LE(worst_cos, 2.0);
    EXPECT_EQ(sincos_quarter(0.f).sin, 0.f);
    EXPECT_EQ(sincos_quarter(0.f).cos, 1.f);
}

TEST(Trig, SinCosTurnsMatchesDoublePrecision) {
    // Every quadrant and its boundaries, negative turns and several periods. An angle's sine near a
    // zero is judged by absolute error: the float t itself is only known to its own spacing.
    double worst = 0;
    constexpr int kSteps = 1 << 20;
    for (int i = 0; i <= kSteps; ++i) {
        const float t = float(-2.0 + 5.0 * double(i) / kSteps);
        const SinCos r = sincos_turns(t);
        const double a = 2 * M_PI * double(t);
        worst = std::max({worst, std::abs(r.sin - std::sin(a)), std::abs(r.cos - std::cos(a))});
    }
    EXPECT_LE(worst * 0x1p24, 3.0);  // absolute error, in units of 2^-24
    // Exact at the quarter turns, where the reduction leaves nothing.
    for (float t : {0.f, 0.25f, 0.5f, 0.75f, 1.f, -0.25f}) {
        const SinCos r = sincos_turns(t);
        EXPECT_EQ(std::abs(r.sin) + std::abs(r.cos), 1.f) << t;
        EXPECT_EQ(r.sin, float(std::round(std::sin(2 * M_PI * t)))) << t;
        EXPECT_EQ(r.cos, float(std::round(std::cos(2 * M_PI * t)))) << t;
    }
}

TEST(Trig, ConcentricDiskMatchesItsAngleForm) {
    constexpr int n = 257;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const Vec2 u(float(i) / (n - 1), float(j) / (n - 1));
            const Vec2 p = square_to_uniform_disk_concentric(u);
            const double a = 2.0 * u.x - 1, b = 2.0 * u.y - 1;
            double r = 0, phi = 0;
            if (a != 0 || b != 0) {
                if (std::abs(a) > std::abs(b)) r = a, phi = M_PI / 4 * (b / a);
                else r = b, phi = M_PI / 2 - M_PI / 4 * (a / b);
            }
            EXPECT_NEAR(p.x, r * std::cos(phi), 3e-7) << u.x << " " << u.y;
            EXPECT_NEAR(p.y, r * std::sin(phi), 3e-7) << u.x << " " << u.y;
        }
}

}  // namespace
}  // namespace neepp::test
