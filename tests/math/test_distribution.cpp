// Distribution1D and Distribution2D: sampling frequencies against pmf/pdf, zero-weight entries, the reused
// remainder of discrete sampling, and normalization.
#include <gtest/gtest.h>

#include "common/chi2.h"
#include "neepp/math/distribution.h"

namespace neepp::test {
namespace {

// Zero weights at the start, in the middle, in a run and at the end: the places where a cdf search slips.
const std::vector<float> kWeights = {0.f, 3.f, 0.f, 1.f, 5.f, 0.f, 0.f, 0.5f, 2.f, 0.f};
constexpr uint64_t kSamples = 200000;
constexpr double kMinP = 1e-4;  // p-value threshold: one false alarm in 10^4 runs per test

TEST(Distribution1D, PmfIsNormalizedWeight) {
    Distribution1D d(kWeights);
    double total = 0;
    for (float w : kWeights) total += w;
    EXPECT_FLOAT_EQ(d.total(), float(total));
    for (uint32_t i = 0; i < kWeights.size(); ++i) EXPECT_FLOAT_EQ(d.pmf(i), float(kWeights[i] / total));
}

TEST(Distribution1D, DiscreteFrequenciesMatchPmf) {
    Distribution1D d(kWeights);
    PCG32 rng(7, 1);
    std::vector<double> observed(kWeights.size(), 0.0), expected(kWeights.size());
    for (uint64_t s = 0; s < kSamples; ++s) {
        float pmf;
        uint32_t i = d.sample_discrete(rng.next_float(), &pmf);
        ASSERT_LT(i, kWeights.size());
        ASSERT_EQ(pmf, d.pmf(i));
        observed[i] += 1;
    }
    for (uint32_t i = 0; i < kWeights.size(); ++i) expected[i] = d.pmf(i) * double(kSamples);
    Chi2Result r = chi2_from_histograms(observed, expected);
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, kMinP) << r.describe();
}

TEST(Distribution1D, ZeroWeightEntriesAreNeverSampled) {
    Distribution1D d(kWeights);
    // A dense sweep plus the extremes and the exact cdf steps, where ties decide the index.
    std::vector<float> us = {0.f, 1e-30f, 0.99999994f};
    double cdf = 0, total = d.total();
    for (float w : kWeights) {
        cdf += w / total;
        for (float u : {float(cdf), std::nextafter(float(cdf), 0.f), std::nextafter(float(cdf), 1.f)})
            if (u < 1.f) us.push_back(u);
    }
    for (int k = 0; k < 100000; ++k) us.push_back(float(k) / 100000.f);
    for (float u : us) {
        uint32_t i = d.sample_discrete(u);
        EXPECT_GT(kWeights[i], 0.f) << "u=" << u << " gave index " << i;
        float ur = u;
        EXPECT_GT(kWeights[d.sample_reuse(ur)], 0.f) << "u=" << u;
        EXPECT_GE(ur, 0.f);
        EXPECT_LT(ur, 1.f);
    }
}

TEST(Distribution1D, SampleReuseLeavesUniformRemainder) {
    // Within each chosen index the rescaled u must be uniform, or a second decision built on it (the
    // point inside a chosen triangle) is biased: bin (index, remainder) jointly.
    Distribution1D d(kWeights);
    constexpr int kSub = 16;
    PCG32 rng(11, 3);
    std::vector<double> observed(kWeights.size() * kSub, 0.0), expected(observed.size());
    for (uint64_t s = 0; s < kSamples; ++s) {
        float u = rng.next_float(), pmf;
        uint32_t i = d.sample_reuse(u, &pmf);
        ASSERT_EQ(pmf, d.pmf(i));
        ASSERT_GE(u, 0.f);
        ASSERT_LT(u, 1.f);
        observed[i * kSub + std::min(int(u * kSub), kSub - 1)] += 1;
    }
    for (size_t k = 0; k < expected.size(); ++k) expected[k] = d.pmf(uint32_t(k / kSub)) * double(kSamples) / kSub;
    Chi2Result r = chi2_from_histograms(observed, expected);
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, kMinP) << r.describe();
}

TEST(Distribution1D, ContinuousFrequenciesMatchPdf) {
    Distribution1D d(kWeights);
    const int n = int(kWeights.size()), kSub = 8;  // sub-bins reveal non-uniformity inside a cell
    PCG32 rng(13, 5);
    std::vector<double> observed(n * kSub, 0.0), expected(n * kSub);
    for (uint64_t s = 0; s < kSamples; ++s) {
        float pdf;
        uint32_t index;
        float x = d.sample_continuous(rng.next_float(), &pdf, &index);
        ASSERT_GE(x, 0.f);
        ASSERT_LT(x, 1.f);
        ASSERT_EQ(index, uint32_t(x * float(n)));
        ASSERT_EQ(pdf, d.pdf_continuous(x));
        observed[std::min(int(x * float(n * kSub)), n * kSub - 1)] += 1;
    }
    double integral = 0;
    for (int k = 0; k < n * kSub; ++k) {
        double mass = d.pdf_continuous((float(k) + 0.5f) / float(n * kSub)) / double(n * kSub);
        expected[k] = mass * double(kSamples);
        integral += mass;
    }
    EXPECT_NEAR(integral, 1.0, 1e-6);
    Chi2Result r = chi2_from_histograms(observed, expected);
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, kMinP) << r.describe();
}

TEST(Distribution1D, AllZeroWeightsGiveZeroPmf) {
    Distribution1D d(std::vector<float>{0.f, 0.f, 0.f});
    float pmf = 1;
    uint32_t i = d.sample_discrete(0.5f, &pmf);
    EXPECT_LT(i, 3u);
    EXPECT_EQ(pmf, 0.f);
}

// A random 8x5 grid with a zero row and a zero column segment, so the marginal and the conditionals both
// have entries that must never be chosen.
Distribution2D random_grid(int w, int h) {
    PCG32 rng(17, 9);
    std::vector<float> weights(size_t(w) * h);
    for (float &v : weights) v = rng.next_float() * rng.next_float() * 10.f;
    for (int x = 0; x < w; ++x) weights[size_t(2) * w + x] = 0.f;
    for (int y = 0; y < h; ++y) weights[size_t(y) * w + 5] = 0.f;
    return Distribution2D(weights, w, h);
}

TEST(Distribution2D, SamplesMatchPdfAndPdfIntegratesToOne) {
    const int w = 8, h = 5, kSub = 2;  // 2x2 sub-bins per cell check uniformity within cells too
    Distribution2D d = random_grid(w, h);
    const int bw = w * kSub, bh = h * kSub;
    PCG32 rng(19, 11);
    std::vector<double> observed(size_t(bw) * bh, 0.0), expected(observed.size());
    for (uint64_t s = 0; s < kSamples; ++s) {
        float pdf;
        Vec2 p = d.sample(rng.next_2d(), &pdf);
        ASSERT_TRUE(p.x >= 0 && p.x < 1 && p.y >= 0 && p.y < 1) << p.x << "," << p.y;
        ASSERT_FLOAT_EQ(pdf, d.pdf(p));
        ASSERT_GT(pdf, 0.f);
        observed[size_t(std::min(int(p.y * bh), bh - 1)) * bw + std::min(int(p.x * bw), bw - 1)] += 1;
    }
    double integral = 0;
    for (int y = 0; y < bh; ++y)
        for (int x = 0; x < bw; ++x) {
            double mass = d.pdf(Vec2((float(x) + 0.5f) / bw, (float(y) + 0.5f) / bh)) / double(bw * bh);
            expected[size_t(y) * bw + x] = mass * double(kSamples);
            integral += mass;
        }
    EXPECT_NEAR(integral, 1.0, 1e-5);
    Chi2Result r = chi2_from_histograms(observed, expected);
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, kMinP) << r.describe();
}

TEST(Distribution2D, RejectsBadDimensions) {
    EXPECT_THROW(Distribution2D(std::vector<float>(6, 1.f), 4, 2), std::invalid_argument);
    EXPECT_THROW(Distribution2D(std::vector<float>{}, 0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace neepp::test
