// Small helpers the BSDF tests share: test directions and a relative comparison of colours.
#pragma once
#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include <string>
#include "neepp/math/vec.h"
#include "neepp/sampling/rng.h"

namespace neepp::test {

// A unit direction at theta_deg from the normal (> 90: from inside), at a fixed azimuth off the axes.
inline Vec3 incident(float theta_deg) {
    const float t = theta_deg * kPi / 180.f;
    return Vec3(std::sin(t) * std::cos(0.7f), std::sin(t) * std::sin(0.7f), std::cos(t));
}

// A uniformly random unit direction: over the upper hemisphere (kept off the horizon), or the sphere.
inline Vec3 random_direction(PCG32 &rng, bool upper) {
    const Vec2 u = rng.next_2d();
    const float z = upper ? 0.02f + 0.98f * u.y : 1.f - 2.f * u.y, r = safe_sqrt(1 - z * z), phi = 2 * kPi * u.x;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// Each channel of a within tol of b's, relative (floored at 1e-4).
inline void expect_rel(const Color &a, const Color &b, float tol, const std::string &what) {
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(a[i], b[i], tol * std::max(1e-4f, std::abs(b[i]))) << what << " [" << i << "]";
}

}  // namespace neepp::test
