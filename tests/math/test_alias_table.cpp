// The alias table must stay unbiased for tables with millions of bins (environment maps), where one
// float's 24 bits cannot both pick the bin and decide between it and its alias.
#include <gtest/gtest.h>
#include <cmath>
#include "neepp/math/distribution.h"
#include "neepp/sampling/rng.h"

using namespace neepp;

TEST(AliasTable, LargeTableFrequenciesMatchWeights) {
    const size_t n = 3'000'017;  // not a power of two, > 2^21
    std::vector<float> w(n);
    for (size_t i = 0; i < n; ++i) w[i] = (i % 2 == 0) ? 1.f : 0.3f;
    AliasTable table(w);
    PCG32 rng(7, 3);
    const int samples = 2'000'000;
    int even = 0;
    double offset_sum = 0;
    for (int k = 0; k < samples; ++k) {
        Vec2 off;
        uint32_t i = table.sample(rng.next_2d(), off);
        ASSERT_LT(i, n);
        even += (i % 2 == 0);
        offset_sum += off.x + off.y;
        ASSERT_TRUE(off.x >= 0 && off.x < 1 && off.y >= 0 && off.y < 1);
    }
    double p_even = 1.0 / 1.3, observed = double(even) / samples;
    double sigma = std::sqrt(p_even * (1 - p_even) / samples);
    EXPECT_NEAR(observed, p_even, 5 * sigma);
    EXPECT_NEAR(offset_sum / (2.0 * samples), 0.5, 0.002);
}

TEST(AliasTable, PmfAndZeroWeights) {
    AliasTable t(std::vector<float>{0.f, 2.f, 0.f, 6.f});
    EXPECT_FLOAT_EQ(t.pmf(1), 0.25f);
    EXPECT_FLOAT_EQ(t.pmf(3), 0.75f);
    EXPECT_EQ(t.pmf(0), 0.f);
    PCG32 rng(1, 1);
    int counts[4] = {0, 0, 0, 0};
    for (int k = 0; k < 100000; ++k) {
        Vec2 off;
        counts[t.sample(rng.next_2d(), off)]++;
    }
    EXPECT_EQ(counts[0], 0);
    EXPECT_EQ(counts[2], 0);
    EXPECT_NEAR(counts[3] / 100000.0, 0.75, 0.007);
    EXPECT_THROW(AliasTable(std::vector<float>{0.f, 0.f}), std::invalid_argument);
}
