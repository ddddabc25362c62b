// Warps from the unit square: each sampler's directions against its density (chi-square over the sphere),
// the triangle warp's uniformity, and the harness's power to reject a warp that disagrees with its pdf.
#include <gtest/gtest.h>

#include "common/chi2.h"
#include "neepp/math/warp.h"

namespace neepp::test {
namespace {

constexpr double kMinP = 1e-4;

SphereChi2Config config(uint64_t seed) {
    SphereChi2Config cfg;
    cfg.res = 41;
    cfg.sample_count = 200000;
    cfg.seed = seed;
    return cfg;
}

DirectionSampler from_warp(Vec3 (*warp)(Vec2)) {
    return [warp](PCG32 &rng) -> std::optional<Vec3> { return warp(rng.next_2d()); };
}

void expect_fits(const DirectionSampler &sample, const DirectionPdf &pdf, const SphereChi2Config &cfg) {
    Chi2Result r = chi2_sphere_test(sample, pdf, cfg);
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, kMinP) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << r.describe();
}

TEST(Warp, CosineHemisphere) {
    expect_fits(from_warp(square_to_cosine_hemisphere),
                [](const Vec3 &w) { return double(square_to_cosine_hemisphere_pdf(w)); }, config(1));
}

TEST(Warp, UniformSphere) {
    expect_fits(from_warp(square_to_uniform_sphere),
                [](const Vec3 &) { return double(square_to_uniform_sphere_pdf()); }, config(2));
}

TEST(Warp, UniformHemisphere) {
    // Binned over the upper hemisphere only: Simpson's rule cannot integrate the density's jump at the
    // horizon, and the lower hemisphere is covered by the samples-outside-the-cap check.
    SphereChi2Config cfg = config(3);
    cfg.cos_min = 0.0;
    expect_fits(from_warp(square_to_uniform_hemisphere),
                [](const Vec3 &w) { return w.z >= 0 ? double(square_to_uniform_hemisphere_pdf()) : 0.0; }, cfg);
}

TEST(Warp, UniformCone) {
    const float cos_max = std::cos(20.f * kPi / 180.f);
    SphereChi2Config cfg = config(4);
    cfg.cos_min = cos_max;  // bin the cone only, so that its narrow support spans many bins
    expect_fits([&](PCG32 &rng) -> std::optional<Vec3> { return square_to_uniform_cone(rng.next_2d(), cos_max); },
                [&](const Vec3 &w) { return w.z >= cos_max ? double(square_to_uniform_cone_pdf(cos_max)) : 0.0; }, cfg);
}

TEST(Warp, ConcentricDiskStaysInDiskAndKeepsCenter) {
    EXPECT_EQ(square_to_uniform_disk_concentric(Vec2(0.5f, 0.5f)).x, 0.f);
    PCG32 rng(5, 5);
    for (int k = 0; k < 10000; ++k) {
        Vec2 d = square_to_uniform_disk_concentric(rng.next_2d());
        ASSERT_LE(d.x * d.x + d.y * d.y, 1.f + 1e-6f);
    }
}

TEST(Warp, UniformTriangle) {
    // Barycentrics (b1, b2) uniform over the triangle b1, b2 >= 0, b1 + b2 <= 1 of the unit square: on an
    // n x n grid, cells below the diagonal hold area 1/n^2, cells it cuts in half 1/(2n^2).
    const int n = 20;
    const uint64_t samples = 200000;
    std::vector<double> observed(n * n, 0.0), expected(n * n, 0.0);
    PCG32 rng(6, 6);
    double mean1 = 0, mean2 = 0;
    for (uint64_t s = 0; s < samples; ++s) {
        Vec2 b = square_to_uniform_triangle(rng.next_2d());
        ASSERT_TRUE(b.x >= 0 && b.y >= 0 && b.x + b.y <= 1.f + 1e-6f) << b.x << "," << b.y;
        mean1 += b.x;
        mean2 += b.y;
        observed[std::min(int(b.y * n), n - 1) * n + std::min(int(b.x * n), n - 1)] += 1;
    }
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            double area = x + y < n - 1 ? 1.0 : (x + y == n - 1 ? 0.5 : 0.0);
            expected[y * n + x] = 2.0 * area / (n * n) * double(samples);  // density 2 on area 1/2
        }
    Chi2Result r = chi2_from_histograms(observed, expected);
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, kMinP) << r.describe();
    // The centroid is (1/3, 1/3); the standard deviation of each coordinate is sqrt(1/18).
    const double tol = 5.0 * std::sqrt(1.0 / 18.0 / double(samples));
    EXPECT_NEAR(mean1 / double(samples), 1.0 / 3.0, tol);
    EXPECT_NEAR(mean2 / double(samples), 1.0 / 3.0, tol);
}

TEST(Chi2Harness, RejectsWarpThatDisagreesWithPdf) {
    // Uniform hemisphere samples judged against the cosine density must fail, or the tests above prove
    // nothing.
    Chi2Result r = chi2_sphere_test(from_warp(square_to_uniform_hemisphere),
                                    [](const Vec3 &w) { return double(square_to_cosine_hemisphere_pdf(w)); },
                                    config(7));
    EXPECT_TRUE(!r.error.empty() || r.p_value < 1e-6) << r.describe();
}

TEST(Warp, MisPowerHeuristic) {
    EXPECT_FLOAT_EQ(mis_power(1.f, 1.f), 0.5f);
    EXPECT_FLOAT_EQ(mis_power(3.f, 1.f), 0.9f);
    EXPECT_FLOAT_EQ(mis_power(1.f, 3.f) + mis_power(3.f, 1.f), 1.f);
    EXPECT_EQ(mis_power(0.f, 0.f), 0.f);
}

}  // namespace
}  // namespace neepp::test
