// Samplers: reproducibility per (pixel, sample index), range, Sobol's per-pixel stratification, and the
// uniformity and independence of later dimensions.
#include <gtest/gtest.h>

#include "neepp/sampling/sampler.h"

namespace neepp::test {
namespace {

const char *kSamplers[] = {"independent", "sobol"};

// The dimensions a path consumes, in a mixed order of 1D and 2D requests as the integrator makes them.
std::vector<float> draw_path(Sampler &s, int pairs) {
    std::vector<float> v;
    for (int k = 0; k < pairs; ++k) {
        Vec2 p = s.next_2d();
        v.push_back(p.x);
        v.push_back(p.y);
        v.push_back(s.next_1d());
    }
    return v;
}

TEST(Sampler, SameSetupGivesSameNumbers) {
    for (const char *name : kSamplers) {
        SCOPED_TRACE(name);
        auto a = make_sampler(name, 42);
        auto b = a->clone();
        // b has been used for another pixel first: state from earlier samples must not leak.
        b->start_sample(9, 9, 3);
        draw_path(*b, 5);
        a->start_sample(17, 4, 11);
        b->start_sample(17, 4, 11);
        EXPECT_EQ(draw_path(*a, 8), draw_path(*b, 8));
        // A different pixel, index or seed changes the numbers.
        auto first = [&](Sampler &s, uint32_t px, uint32_t py, uint32_t i) {
            s.start_sample(px, py, i);
            return draw_path(s, 2);
        };
        std::vector<float> ref = first(*a, 17, 4, 11);
        EXPECT_NE(first(*a, 18, 4, 11), ref);
        EXPECT_NE(first(*a, 17, 5, 11), ref);
        EXPECT_NE(first(*a, 17, 4, 12), ref);
        auto c = make_sampler(name, 43);
        EXPECT_NE(first(*c, 17, 4, 11), ref);
    }
}

TEST(Sampler, ValuesInUnitInterval) {
    for (const char *name : kSamplers) {
        auto s = make_sampler(name, 1);
        for (uint32_t i = 0; i < 2000; ++i) {
            s->start_sample(i % 37, i / 37, i);
            for (float v : draw_path(*s, 10)) {
                ASSERT_GE(v, 0.f) << name;
                ASSERT_LT(v, 1.f) << name;
            }
        }
    }
}

TEST(Sampler, UnknownNameThrowsAndAliasesMapToSobol) {
    EXPECT_THROW(make_sampler("halton", 0), std::invalid_argument);
    EXPECT_EQ(make_sampler("multijitter", 0)->name(), "sobol");
    EXPECT_EQ(make_sampler("independent", 0)->name(), "independent");
}

// Every elementary interval of area 1/64 (1x64, 2x32, ..., 64x1 cells) holds exactly one of the 64
// points: the (0,6,2)-net property that Owen-scrambled Sobol keeps for each aligned block of indices.
void expect_net(const std::vector<Vec2> &pts) {
    ASSERT_EQ(pts.size(), 64u);
    for (int log_x = 0; log_x <= 6; ++log_x) {
        int nx = 1 << log_x, ny = 64 / nx;
        std::vector<int> count(64, 0);
        for (const Vec2 &p : pts) ++count[int(p.y * float(ny)) * nx + int(p.x * float(nx))];
        for (int c = 0; c < 64; ++c) EXPECT_EQ(count[c], 1) << nx << "x" << ny << " grid, cell " << c;
    }
}

TEST(SobolSampler, EachDimensionPairIsStratifiedPerPixel) {
    SobolSampler s(7);
    for (uint32_t pixel = 0; pixel < 4; ++pixel)
        for (uint32_t block = 0; block < 2; ++block) {  // indices 0..63, then 64..127
            constexpr int kPairs = 6;
            std::vector<std::vector<Vec2>> pts(kPairs);
            std::vector<float> ones;
            for (uint32_t i = 0; i < 64; ++i) {
                s.start_sample(pixel * 3, pixel, block * 64 + i);
                for (int d = 0; d < kPairs; ++d) pts[d].push_back(s.next_2d());
                ones.push_back(s.next_1d());
            }
            for (int d = 0; d < kPairs; ++d) {
                SCOPED_TRACE("pixel " + std::to_string(pixel) + " block " + std::to_string(block) + " pair " +
                             std::to_string(d));
                expect_net(pts[d]);
            }
            // A 1D dimension is stratified into 64 intervals likewise.
            std::vector<int> count(64, 0);
            for (float v : ones) ++count[int(v * 64.f)];
            for (int c = 0; c < 64; ++c) EXPECT_EQ(count[c], 1) << "1D interval " << c;
        }
}

TEST(Sampler, LaterDimensionsAreUniformAndUncorrelated) {
    // Over many pixels and samples each dimension must have the mean and variance of U[0,1), and no two
    // dimensions may be correlated (each dimension pair has its own scrambling hash).
    constexpr int kDims = 48, kPixels = 64 * 64, kSpp = 16;
    const double n = double(kPixels) * kSpp;
    const double mean_tol = 5.0 * std::sqrt(1.0 / 12.0 / n);
    const double var_tol = 5.0 * std::sqrt((1.0 / 80.0 - 1.0 / 144.0) / n);
    const double corr_tol = 5.0 * std::sqrt(1.0 / 144.0 / n) * 12.0;  // correlation of independent uniforms
    for (const char *name : kSamplers) {
        SCOPED_TRACE(name);
        auto s = make_sampler(name, 3);
        std::vector<double> sum(kDims, 0.0), sum2(kDims, 0.0), cross(kDims * kDims, 0.0);
        for (uint32_t p = 0; p < uint32_t(kPixels); ++p)
            for (uint32_t i = 0; i < uint32_t(kSpp); ++i) {
                s->start_sample(p % 64, p / 64, i);
                std::vector<float> v = draw_path(*s, kDims / 3);
                for (int d = 0; d < kDims; ++d) {
                    double c = v[d] - 0.5;
                    sum[d] += c;
                    sum2[d] += c * c;
                    for (int e = d + 1; e < kDims; ++e) cross[d * kDims + e] += c * (v[e] - 0.5);
                }
            }
        for (int d = 0; d < kDims; ++d) {
            EXPECT_NEAR(sum[d] / n, 0.0, mean_tol) << "dimension " << d;
            EXPECT_NEAR(sum2[d] / n, 1.0 / 12.0, var_tol) << "dimension " << d;
            for (int e = d + 1; e < kDims; ++e)
                EXPECT_NEAR(12.0 * cross[d * kDims + e] / n, 0.0, corr_tol) << "dimensions " << d << "," << e;
        }
    }
}

}  // namespace
}  // namespace neepp::test
