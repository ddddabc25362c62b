// The directional quadtree of the SD-tree: its sampling follows its density (chi-square, and the density
// of each sample is the one pdf() gives, to the bit), the density integrates to one and is zero exactly
// where no energy was recorded, and refinement subdivides where the energy is.
#include <gtest/gtest.h>
#include <cmath>
#include "common/chi2.h"
#include "neepp/guiding/directional_quadtree.h"
#include "neepp/sampling/rng.h"

using namespace neepp;

namespace {

constexpr int kMaxDepth = 7;  // cells no smaller than 2^-7: a 128 × 128 grid resolves every leaf exactly

// A tree learned as the SD-tree learns one: energies recorded at points drawn from a lumpy density (a
// narrow peak, a broad bump, and nothing at v > 0.8), summed per leaf, refined, three times over.
DirectionalQuadtree learned_tree(uint64_t seed, int max_depth = kMaxDepth) {
    PCG32 rng(seed, 3);
    DirectionalQuadtree tree;
    tree = tree.refined(0.01, max_depth);
    for (int round = 0; round < 4; ++round) {
        std::vector<double> sums(tree.slot_count(), 0.0);
        for (int i = 0; i < 20000; ++i) {
            double u, v;
            if (rng.next_float() < 0.3f) {
                u = 0.71 + 0.02 * rng.next_float();
                v = 0.23 + 0.01 * rng.next_float();
            } else {
                u = rng.next_float();
                v = 0.8 * rng.next_float();
            }
            sums[tree.leaf_slot(u, v)] += 1.0 + 3.0 * u;
        }
        tree.set_leaf_sums(sums);
        if (round < 3) tree = tree.refined(0.01, max_depth);
    }
    return tree;
}

TEST(DirectionalQuadtree, EmptyTreeRefinesUniformly) {
    // Each quadrant at depth d holds 4^-d of nothing: split while that is over 1%, i.e. down to depth 4.
    const DirectionalQuadtree t = DirectionalQuadtree().refined(0.01, 20);
    EXPECT_EQ(t.depth(), 4);
    EXPECT_EQ(t.leaf_count(), 256u);
    EXPECT_EQ(t.total(), 0.0);
    EXPECT_EQ(t.pdf(0.3, 0.4), 0.0) << "no energy, no density";
}

TEST(DirectionalQuadtree, RefinesWhereTheEnergyIs) {
    const DirectionalQuadtree t = learned_tree(1, 20);
    EXPECT_GT(t.depth(), 6) << "the narrow peak is resolved";
    EXPECT_LT(t.leaf_count(), 2000u) << "and the rest is not split as finely";
    // Every quadrant that was split held more than 1% of the energy, every leaf at most 1% unless at the
    // depth limit: the refined tree's cells, judged by the energy they were refined from.
    const DirectionalQuadtree next = t.refined(0.01, 20);
    const double total = t.total();
    int big_leaves = 0;
    for (size_t n = 0; n < next.nodes().size(); ++n)
        for (int q = 0; q < 4; ++q)
            if (!next.nodes()[n].child[q]) ++big_leaves;
    EXPECT_EQ(size_t(big_leaves), next.leaf_count());
    // A peak cell: deep in `next`, a flat cell: shallow.
    auto depth_at = [&](double u, double v) {
        int d = 1;
        uint32_t node = 0;
        for (;;) {
            const int q = (u >= 0.5) | ((v >= 0.5) << 1);
            u = 2 * u - (u >= 0.5);
            v = 2 * v - (v >= 0.5);
            if (!next.nodes()[node].child[q]) return d;
            node = next.nodes()[node].child[q];
            ++d;
        }
    };
    EXPECT_GE(depth_at(0.72, 0.235), 7);
    EXPECT_LE(depth_at(0.1, 0.95), 3) << "no energy at v > 0.8: coarse there";
    EXPECT_GT(total, 0);
}

TEST(DirectionalQuadtree, DensityIntegratesToOneAndIsZeroOnlyWithoutEnergy) {
    const DirectionalQuadtree t = learned_tree(2);
    const int n = 1 << kMaxDepth;
    double integral = 0;
    int zero = 0, positive_without_energy = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double u = (x + 0.5) / n, v = (y + 0.5) / n;
            const double p = t.pdf(u, v);
            integral += p / (double(n) * n);
            const uint32_t slot = t.leaf_slot(u, v);
            const double energy = t.nodes()[slot / 4].sum[slot % 4];
            if (p == 0) ++zero;
            if ((p > 0) != (energy > 0)) ++positive_without_energy;
        }
    EXPECT_NEAR(integral, 1.0, 1e-12);
    EXPECT_GT(zero, 0) << "v > 0.8 got no energy";
    EXPECT_EQ(positive_without_energy, 0);
}

TEST(DirectionalQuadtree, SampleDensityIsPdfToTheBit) {
    const DirectionalQuadtree t = learned_tree(3);
    PCG32 rng(9, 1);
    for (int i = 0; i < 200000; ++i) {
        const double u0 = rng.next_float(), u1 = rng.next_float();
        const DirectionalQuadtree::Sample s = t.sample(u0, u1);
        ASSERT_GE(s.u, 0.0);
        ASSERT_LT(s.u, 1.0);
        ASSERT_GE(s.v, 0.0);
        ASSERT_LT(s.v, 1.0);
        ASSERT_GT(s.pdf, 0.0) << "never where there is no energy";
        ASSERT_EQ(s.pdf, t.pdf(s.u, s.v)) << u0 << " " << u1;
    }
    // The edges of the unit interval.
    for (double u0 : {0.0, std::nextafter(1.0, 0.0)})
        for (double u1 : {0.0, std::nextafter(1.0, 0.0)}) {
            const DirectionalQuadtree::Sample s = t.sample(u0, u1);
            EXPECT_EQ(s.pdf, t.pdf(s.u, s.v));
            EXPECT_GT(s.pdf, 0.0);
        }
}

// Pearson's test on the 128 × 128 grid of the finest cells: each cell's expected count is its density ×
// area exactly (the density is constant in it).
test::Chi2Result chi2_of(const DirectionalQuadtree &t, uint64_t seed) {
    const int n = 1 << kMaxDepth;
    std::vector<double> observed(size_t(n) * n, 0.0), expected(size_t(n) * n, 0.0);
    const int samples = 1000000;
    PCG32 rng(seed, 5);
    for (int i = 0; i < samples; ++i) {
        const DirectionalQuadtree::Sample s = t.sample(rng.next_float(), rng.next_float());
        observed[size_t(s.v * n) * n + size_t(s.u * n)] += 1;
    }
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) expected[size_t(y) * n + x] = t.pdf((x + 0.5) / n, (y + 0.5) / n) / (double(n) * n) * samples;
    return test::chi2_from_histograms(observed, expected);
}

TEST(DirectionalQuadtree, ChiSquareOfSamplingAgainstDensity) {
    for (uint64_t seed : {4u, 5u, 6u}) {
        const test::Chi2Result r = chi2_of(learned_tree(seed), seed);
        EXPECT_TRUE(r.error.empty()) << r.error;
        EXPECT_GT(r.p_value, 0.01 / 3) << r.describe();
    }
}

// The test can fail: a sampler that draws from one tree, judged against another's density.
TEST(DirectionalQuadtree, ChiSquareSeesAWrongDensity) {
    const DirectionalQuadtree a = learned_tree(7);
    DirectionalQuadtree b = a;
    std::vector<double> sums(b.slot_count(), 0.0);
    for (size_t n = 0; n < b.nodes().size(); ++n)
        for (int q = 0; q < 4; ++q) sums[n * 4 + q] = b.nodes()[n].sum[q] * (q == 0 ? 1.1 : 1.0);
    b.set_leaf_sums(sums);  // the first quadrant of every node 10% heavier
    const int n = 1 << kMaxDepth;
    std::vector<double> observed(size_t(n) * n, 0.0), expected(size_t(n) * n, 0.0);
    PCG32 rng(8, 5);
    for (int i = 0; i < 1000000; ++i) {
        const DirectionalQuadtree::Sample s = b.sample(rng.next_float(), rng.next_float());
        observed[size_t(s.v * n) * n + size_t(s.u * n)] += 1;
    }
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) expected[size_t(y) * n + x] = a.pdf((x + 0.5) / n, (y + 0.5) / n) / (double(n) * n) * 1e6;
    const test::Chi2Result r = test::chi2_from_histograms(observed, expected);
    EXPECT_LT(r.p_value, 1e-6) << r.describe();
}

TEST(DirectionalQuadtree, CylindricalMappingRoundTrips) {
    PCG32 rng(2, 2);
    for (int i = 0; i < 10000; ++i) {
        const double u = rng.next_float(), v = rng.next_float();
        const Vec3 d = square_to_direction(u, v);
        EXPECT_NEAR(d.x * d.x + d.y * d.y + d.z * d.z, 1.0, 1e-6);
        double u2, v2;
        direction_to_square(d, u2, v2);
        EXPECT_NEAR(u2, u, 1e-6);
        EXPECT_NEAR(std::min(std::abs(v2 - v), 1 - std::abs(v2 - v)), 0.0, 1e-6);
    }
}

TEST(DirectionalQuadtree, SerializesExactly) {
    const DirectionalQuadtree t = learned_tree(11);
    std::string bytes;
    t.write(bytes);
    size_t offset = 0;
    EXPECT_TRUE(DirectionalQuadtree::read(bytes, offset) == t);
    EXPECT_EQ(offset, bytes.size());
    offset = 0;
    EXPECT_THROW(DirectionalQuadtree::read(std::string_view(bytes).substr(0, bytes.size() - 3), offset), std::runtime_error);
}

}  // namespace
