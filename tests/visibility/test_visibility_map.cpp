// The visibility map's storage, estimate and update rules, the per-thread update buffer, and the
// probability rule of every NEE++ policy (q is never 0 where visibility can be 1).
#include <gtest/gtest.h>
#include <cmath>
#include <limits>
#include <map>
#include "neepp/sampling/rng.h"
#include "neepp/visibility/neepp_shadow_rays.h"
#include "neepp/visibility/update_buffer.h"
#include "neepp/visibility/visibility_map.h"

using namespace neepp;

namespace {

TEST(VisibilityMap, SymmetricPairsShareOneEntry) {
    VisibilityMap m(100);
    EXPECT_EQ(m.pair_count(), 100u * 101u / 2u);
    PCG32 rng(3, 4);
    for (int i = 0; i < 1000; ++i) {
        uint32_t a = rng.next_u32() % 100, b = rng.next_u32() % 100;
        EXPECT_EQ(VisibilityMap::pair_index(a, b), VisibilityMap::pair_index(b, a));
        EXPECT_LT(VisibilityMap::pair_index(a, b), m.pair_count());
    }
    m.add(7, 42, 3, 5);
    EXPECT_EQ(m.counts(42, 7).visible, 3);
    EXPECT_EQ(m.counts(42, 7).traced, 5);
    EXPECT_EQ(m.counts(7, 42).traced, 5);
    EXPECT_FALSE(m.known(7, 43));
    EXPECT_TRUE(m.known(42, 7));
    EXPECT_EQ(m.known_pairs(), 1u);
    // All indices distinct: the triangle layout is a bijection.
    std::vector<int> seen(m.pair_count(), 0);
    for (uint32_t a = 0; a < 100; ++a)
        for (uint32_t b = 0; b <= a; ++b) ++seen[VisibilityMap::pair_index(a, b)];
    for (int s : seen) ASSERT_EQ(s, 1);
}

TEST(VisibilityMap, SixteenCubedFitsTheBudget) {
    VisibilityMap m(16 * 16 * 16 + VoxelGrid::kDirectionBins);
    EXPECT_LE(m.memory_bytes(), 36u * 1000u * 1000u);  // the slides' ~35 MB
}

TEST(VisibilityMap, EstimateHasWeakPriorNeverZeroOrOne) {
    EXPECT_FLOAT_EQ(VisibilityMap::estimate(PairCounts{0, 16}), 1.f / 18.f);
    EXPECT_FLOAT_EQ(VisibilityMap::estimate(PairCounts{16, 16}), 17.f / 18.f);
    EXPECT_FLOAT_EQ(VisibilityMap::estimate(PairCounts{8, 16}), 0.5f);
    EXPECT_GT(VisibilityMap::estimate(PairCounts{0, 65535}), 0.f);
    EXPECT_LT(VisibilityMap::estimate(PairCounts{65535, 65535}), 1.f);
}

TEST(VisibilityMap, SaturationHalvesBothCounts) {
    VisibilityMap m(4);
    m.add(1, 2, 30000, 60000);
    m.add(1, 2, 10000, 10000);  // 40000 / 70000 -> halved to 20000 / 35000
    EXPECT_EQ(m.counts(1, 2).visible, 20000);
    EXPECT_EQ(m.counts(1, 2).traced, 35000);
    m.add(2, 1, 0, 1u << 30);  // a huge merge keeps halving until it fits
    EXPECT_LE(m.counts(1, 2).traced, VisibilityMap::kMaxCount);
    EXPECT_LE(m.counts(1, 2).visible, m.counts(1, 2).traced);
}

TEST(PairUpdateBuffer, SumsMatchAReferenceMap) {
    PairUpdateBuffer buf;
    std::map<uint64_t, std::pair<uint32_t, uint32_t>> ref;
    PCG32 rng(5, 6);
    buf.reserve(10);
    for (int i = 0; i < 200000; ++i) {
        if (i == 1000) buf.reserve(60000);  // re-slots what it holds; nothing lost or doubled
        uint64_t pair = rng.next_u32() % 50000;
        bool vis = rng.next_float() < 0.3f;
        buf.record(pair, vis);
        ref[pair].first += vis;
        ref[pair].second += 1;
    }
    EXPECT_EQ(buf.size(), ref.size());
    size_t n = 0;
    buf.for_each([&](uint64_t pair, uint32_t v, uint32_t t) {
        ++n;
        ASSERT_TRUE(ref.count(pair));
        EXPECT_EQ(ref[pair].first, v);
        EXPECT_EQ(ref[pair].second, t);
    });
    EXPECT_EQ(n, ref.size());
    buf.clear();
    EXPECT_EQ(buf.size(), 0u);
    size_t left = 0;
    buf.for_each([&](uint64_t, uint32_t, uint32_t) { ++left; });
    EXPECT_EQ(left, 0u) << "cleared buffer is not empty";
}

// Property test: for every policy, random counts, contributions (including 0, huge, NaN, inf, negative)
// and adaptive scales, q lies in [q_min, 1]: a sample that can be visible is never given probability 0.
TEST(ShadowRayPolicies, TraceProbabilityNeverZero) {
    PCG32 rng(11, 12);
    const float specials[] = {0.f, -1.f, 1e-30f, 1e30f, std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::quiet_NaN(), 1.f};
    for (auto policy : {ShadowRayPolicy::Neepp, ShadowRayPolicy::NeeppAdaptive, ShadowRayPolicy::NeeppCV})
        for (float q_min : {0.01f, 0.05f, 0.3f, 1.f}) {
            NeeppOptions o;
            o.policy = policy;
            o.q_min = q_min;
            NeeppShadowRays tester(o);
            for (double scale : {0.0, 1e-20, 1e-3, 1.0, 1e3, 1e20}) {
                tester.set_adaptive_scale(scale);
                for (int i = 0; i < 20000; ++i) {
                    PairCounts c;
                    c.traced = uint16_t(rng.next_u32() % 65536);
                    c.visible = c.traced ? uint16_t(rng.next_u32() % (c.traced + 1u)) : 0;
                    if (i % 7 == 0) c.visible = 0;  // the dangerous case: a pair the map believes occluded
                    float lum = i < 7 ? specials[i] : std::exp2(rng.next_float() * 80.f - 40.f);
                    bool same = i % 13 == 0;
                    float q = tester.trace_probability(c, same, lum);
                    ASSERT_GE(q, q_min) << to_string(policy) << " counts " << c.visible << "/" << c.traced << " lum " << lum;
                    ASSERT_LE(q, 1.f);
                    if (same || c.traced == 0) {
                        ASSERT_EQ(q, 1.f) << "unknown and same-cell pairs must always be traced";
                    }
                }
            }
        }
}

TEST(ShadowRayPolicies, RejectsBadOptions) {
    NeeppOptions o;
    o.q_min = 0.f;
    EXPECT_THROW(NeeppShadowRays{o}, std::invalid_argument);
    o.q_min = 0.05f;
    o.voxels = 64;
    EXPECT_THROW(NeeppShadowRays{o}, std::invalid_argument);
    EXPECT_THROW(parse_shadow_ray_policy("nee++"), std::invalid_argument);
    EXPECT_EQ(parse_shadow_ray_policy("neepp-cv"), ShadowRayPolicy::NeeppCV);
}

}  // namespace
