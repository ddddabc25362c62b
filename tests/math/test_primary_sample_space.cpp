// PSSMLT's sampler: a state replays to the same numbers, streams do not shift each other, a rejected
// proposal leaves the state as it was, small steps have the size asked for (also when an entry catches
// up on steps it was not read in), and the chain's numbers stay uniform: the stationary distribution of
// a chain that accepts everything is the uniform one, which MLT's target is relative to.
#include <gtest/gtest.h>
#include <cmath>
#include <vector>

#include "neepp/sampling/primary_sample_space.h"

namespace neepp::test {
namespace {

std::vector<float> read(PrimarySampleSpaceSampler &s, int camera, int light, int roulette = 0) {
    s.start_evaluation();
    std::vector<float> v;
    for (int i = 0; i < camera; ++i) v.push_back(s.next_1d());
    s.use_stream(SampleStream::Light);
    for (int i = 0; i < light; ++i) v.push_back(s.next_1d());
    s.use_stream(SampleStream::Roulette);
    for (int i = 0; i < roulette; ++i) v.push_back(s.next_1d());
    return v;
}

// The distance between two numbers on the unit circle (mutations wrap around).
double wrapped(double a, double b) {
    double d = a - b;
    return d - std::round(d);
}

TEST(PrimarySampleSpace, RestartReplaysAndStreamsDoNotShiftEachOther) {
    PrimarySampleSpaceSampler a(0.01f, 0.3f), b(0.01f, 0.3f);
    a.restart(7, 3);
    b.restart(7, 3);
    EXPECT_EQ(read(a, 5, 4), read(b, 5, 4));
    // Evaluated again without a proposal: the same state.
    EXPECT_EQ(read(a, 5, 4), read(b, 5, 4));
    // The light stream's numbers do not depend on how many the camera stream read first.
    PrimarySampleSpaceSampler c(0.01f, 0.3f);
    c.restart(7, 3);
    std::vector<float> more = read(c, 9, 4);
    std::vector<float> ref = read(a, 5, 4);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(ref[5 + i], more[9 + i]);
    // Another seed, other numbers.
    PrimarySampleSpaceSampler d(0.01f, 0.3f);
    d.restart(8, 3);
    EXPECT_NE(read(d, 5, 4), ref);
}

TEST(PrimarySampleSpace, RejectedProposalLeavesTheStateAsItWas) {
    PrimarySampleSpaceSampler s(0.05f, 0.5f);
    s.restart(1, 1);
    const std::vector<float> state = read(s, 6, 6, 2);
    int large = 0;
    for (int k = 0; k < 200; ++k) {
        large += s.propose();
        const std::vector<float> proposal = read(s, 6, 6, 2 + k % 3);  // proposals may read more entries
        EXPECT_NE(proposal, state);
        s.reject();
        EXPECT_EQ(read(s, 6, 6, 2), state) << "after rejecting proposal " << k;
    }
    EXPECT_GT(large, 50);
    EXPECT_LT(large, 150);
}

TEST(PrimarySampleSpace, SmallStepsHaveTheirSizeAlsoWhenCaughtUpLater) {
    const float sigma = 0.01f;
    PrimarySampleSpaceSampler s(sigma, 0.f);  // small steps only
    s.restart(2, 2);
    // Entry 0 is read at every step, entry 1 (the light stream's first) every 16th: it then receives 16
    // steps at once, of standard deviation 4 sigma.
    std::vector<float> prev = read(s, 1, 1);
    double sum0 = 0, sum1 = 0;
    int n0 = 0, n1 = 0;
    float last1 = prev[1];
    for (int k = 1; k <= 16 * 2000; ++k) {
        s.propose();
        const bool both = k % 16 == 0;
        const std::vector<float> v = read(s, 1, both ? 1 : 0);
        s.accept();
        sum0 += std::pow(wrapped(v[0], prev[0]), 2), ++n0;
        if (both) {
            sum1 += std::pow(wrapped(v[1], last1), 2), ++n1;
            last1 = v[1];
        }
        prev = v;
    }
    EXPECT_NEAR(std::sqrt(sum0 / n0), sigma, 0.02 * sigma);
    EXPECT_NEAR(std::sqrt(sum1 / n1), 4 * sigma, 0.05 * 4 * sigma);
}

TEST(PrimarySampleSpace, AChainThatAcceptsEverythingStaysUniform) {
    // Mixed large and small steps, some rejected, entries read irregularly: each entry's values over the
    // chain must be uniform (chi-square over 20 bins, 3 entries).
    PrimarySampleSpaceSampler s(0.1f, 0.2f);
    s.restart(3, 3);
    constexpr int kBins = 20, kSteps = 200000;
    std::vector<std::vector<int>> hist(3, std::vector<int>(kBins));
    for (int k = 0; k < kSteps; ++k) {
        s.propose();
        const std::vector<float> v = read(s, 2, k % 3 == 0 ? 1 : 0);
        if (k % 4 == 3) s.reject();
        else s.accept();
        for (size_t e = 0; e < v.size(); ++e) ++hist[e][std::min(int(v[e] * kBins), kBins - 1)];
        for (float x : v) ASSERT_TRUE(x >= 0.f && x < 1.f) << x;
    }
    for (int e = 0; e < 3; ++e) {
        double total = 0, chi2 = 0;
        for (int c : hist[e]) total += c;
        for (int c : hist[e]) chi2 += std::pow(c - total / kBins, 2) / (total / kBins);
        // The chain's samples are correlated (sigma 0.1), so the effective count is lower than the
        // number of steps: a loose bound, which a bias (a skew toward a wrap's side, say) still exceeds.
        EXPECT_LT(chi2 / (kBins - 1), 8.0) << "entry " << e;
    }
}

}  // namespace
}  // namespace neepp::test
