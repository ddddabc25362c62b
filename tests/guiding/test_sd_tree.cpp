// The SD-tree: directions it samples follow its solid-angle density (chi-square on the sphere), the
// density integrates to one, leaves split where records crowd, and the tree a pass leaves depends on what
// was recorded, not on the order or the threads it came from.
#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include "common/chi2.h"
#include "neepp/guiding/sd_tree.h"
#include "neepp/sampling/rng.h"

using namespace neepp;

namespace {

struct Record {
    Vec3 p, d;
    double value;
};

BBox unit_box() {
    BBox b;
    b.expand(Vec3(-1.f));
    b.expand(Vec3(1.f));
    return b;
}

// Records whose radiance comes mostly from one direction, which depends on the side of the box (x < 0:
// from +y, x > 0: from -z), at points crowded in the x < 0 half.
std::vector<Record> records(uint64_t seed, int n) {
    PCG32 rng(seed, 7);
    std::vector<Record> out;
    for (int i = 0; i < n; ++i) {
        Record r;
        const bool left = rng.next_float() < 0.8f;
        r.p = Vec3((left ? -1.f : 0.f) + rng.next_float(), 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        const Vec3 lobe = left ? Vec3(0, 1, 0) : Vec3(0, 0, -1);
        Vec3 d(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        if (rng.next_float() < 0.7f) d = lobe + d * 0.1f;
        r.d = d / norm(d);
        r.value = 0.5 + rng.next_float() * 2;
        out.push_back(r);
    }
    return out;
}

SDTree trained(const std::vector<Record> &rs, int passes, SDTreeOptions o = {}) {
    SDTree t(unit_box(), o);
    for (int pass = 0; pass < passes; ++pass) {
        for (const Record &r : rs) t.record(r.p, r.d, r.value);
        t.update(1);
    }
    return t;
}

SDTreeOptions small_threshold() {
    SDTreeOptions o;
    o.spatial_threshold = 2000;
    return o;
}

TEST(SDTree, NothingRecordedNothingGuided) {
    SDTree t(unit_box());
    EXPECT_FALSE(t.can_guide(t.leaf_at(Vec3(0.f))));
    t.update(1);
    EXPECT_FALSE(t.can_guide(t.leaf_at(Vec3(0.f))));
    EXPECT_EQ(t.leaf_count(), 1u);
}

TEST(SDTree, LeavesSplitWhereRecordsCrowd) {
    const SDTree t = trained(records(1, 80000), 2, small_threshold());
    EXPECT_GT(t.leaf_count(), 4u);
    // The crowded half (x < 0, four records in five) is split more finely: leaves met on a grid in each.
    std::vector<uint32_t> left, right;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j)
            for (int k = 0; k < 10; ++k) {
                const Vec3 p(-0.99f + 0.098f * float(k), -0.99f + 0.099f * float(i), -0.99f + 0.099f * float(j));
                left.push_back(t.leaf_at(p));
                right.push_back(t.leaf_at(p + Vec3(1.f, 0.f, 0.f)));
            }
    auto distinct = [](std::vector<uint32_t> v) {
        std::sort(v.begin(), v.end());
        return size_t(std::unique(v.begin(), v.end()) - v.begin());
    };
    EXPECT_GT(distinct(left), distinct(right) + 8) << distinct(left) << " " << distinct(right);
    // With the paper's threshold (12000 √spp), 40000 records in one pass split the root twice at most.
    EXPECT_LE(trained(records(1, 40000), 1).leaf_count(), 8u);
}

TEST(SDTree, GuidesTowardWhereRadianceCameFrom) {
    const SDTree t = trained(records(2, 40000), 3, small_threshold());
    const uint32_t left = t.leaf_at(Vec3(-0.5f, 0.f, 0.f)), right = t.leaf_at(Vec3(0.5f, 0.f, 0.f));
    ASSERT_TRUE(t.can_guide(left));
    ASSERT_TRUE(t.can_guide(right));
    EXPECT_GT(t.pdf(left, Vec3(0, 1, 0)), 20 * t.pdf(left, Vec3(0, -1, 0)));
    EXPECT_GT(t.pdf(right, Vec3(0, 0, -1)), 20 * t.pdf(right, Vec3(0, 0, 1)));
}

// Chi-square of the leaf's sampled directions against its solid-angle density, binned over (cos θ, φ) on
// a grid that the quadtree's cells align with (max_depth 7: no cell finer than 2^-7), where each bin's
// expected count is its density times its area exactly.
TEST(SDTree, ChiSquareOfDirectionsAgainstSolidAngleDensity) {
    SDTreeOptions o = small_threshold();
    o.max_depth = 7;
    const SDTree t = trained(records(3, 40000), 3, o);
    for (const Vec3 &p : {Vec3(-0.5f, 0.f, 0.f), Vec3(0.5f, 0.3f, -0.2f)}) {
        const uint32_t leaf = t.leaf_at(p);
        ASSERT_TRUE(t.can_guide(leaf));
        const int n = 128;
        const double two_pi = 6.283185307179586;
        std::vector<double> observed(size_t(n) * n, 0.0), expected(size_t(n) * n, 0.0);
        PCG32 rng(4, 4);
        const int samples = 1000000;
        for (int i = 0; i < samples; ++i) {
            const Vec3 d = t.sample(leaf, rng.next_2d());
            const double c = std::clamp((double(d.z) + 1) / 2, 0.0, std::nextafter(1.0, 0.0));
            double phi = std::atan2(double(d.y), double(d.x));
            if (phi < 0) phi += two_pi;
            const double f = std::min(phi / two_pi, std::nextafter(1.0, 0.0));
            observed[size_t(f * n) * n + size_t(c * n)] += 1;
        }
        // A bin is 4π / n² of solid angle.
        double integral = 0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double phi = two_pi * (y + 0.5) / n, ct = 2 * (x + 0.5) / n - 1, st = std::sqrt(1 - ct * ct);
                const Vec3 d(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct));
                const double mass = double(t.pdf(leaf, d)) * 4 * 3.141592653589793 / (double(n) * n);
                expected[size_t(y) * n + x] = mass * samples;
                integral += mass;
            }
        EXPECT_NEAR(integral, 1.0, 1e-5) << "the density integrates to one over the sphere";
        const test::Chi2Result r = test::chi2_from_histograms(observed, expected);
        EXPECT_TRUE(r.error.empty()) << r.error;
        EXPECT_GT(r.p_value, 0.01 / 2) << r.describe();
    }
}

TEST(SDTree, SameRecordsInAnyOrderMakeTheSameTree) {
    const std::vector<Record> rs = records(5, 30000);
    const SDTree a = trained(rs, 3, small_threshold());
    std::vector<Record> shuffled = rs;
    std::mt19937 g(1);
    std::shuffle(shuffled.begin(), shuffled.end(), g);
    const SDTree b = trained(shuffled, 3, small_threshold());
    EXPECT_TRUE(a == b);
    // From four threads at once.
    SDTree c(unit_box(), small_threshold());
    for (int pass = 0; pass < 3; ++pass) {
        std::vector<std::thread> threads;
        for (int k = 0; k < 4; ++k)
            threads.emplace_back([&, k] {
                for (size_t i = k; i < shuffled.size(); i += 4) c.record(shuffled[i].p, shuffled[i].d, shuffled[i].value);
            });
        for (auto &th : threads) th.join();
        c.update(1);
    }
    EXPECT_TRUE(a == c);
    // And the comparison can fail: one record more.
    SDTree d(unit_box(), small_threshold());
    for (int pass = 0; pass < 3; ++pass) {
        for (const Record &r : rs) d.record(r.p, r.d, r.value);
        if (pass == 2) d.record(rs[0].p, rs[0].d, rs[0].value);
        d.update(1);
    }
    EXPECT_FALSE(a == d);
}

TEST(SDTree, SavesAndLoadsExactly) {
    const SDTree a = trained(records(6, 20000), 3, small_threshold());
    SDTree b(unit_box(), small_threshold());
    b.load(a.save());
    EXPECT_TRUE(a == b);
    BBox other;
    other.expand(Vec3(0.f));
    other.expand(Vec3(5.f));
    SDTree c(other);
    EXPECT_THROW(c.load(a.save()), std::runtime_error) << "another scene's tree";
    EXPECT_THROW(b.load(a.save().substr(0, 100)), std::runtime_error);
}

}  // namespace

namespace {

// Merging what several renders learned: the merged leaf's density at a direction is the energy-weighted
// mixture of theirs, on the union of their spatial leaves; merging is deterministic and a tree merged
// with nothing else guides as it did.
TEST(SDTree, MergeIsTheEnergyWeightedSumOnTheUnionOfLeaves) {
    const SDTree a = trained(records(7, 30000), 2, small_threshold());
    SDTreeOptions coarse = small_threshold();
    coarse.spatial_threshold = 8000;
    const SDTree b = trained(records(8, 20000), 3, coarse);
    const SDTree *both[] = {&a, &b};
    const SDTree merged = SDTree::merge(both);
    EXPECT_GE(merged.leaf_count(), std::max(a.leaf_count(), b.leaf_count()));
    EXPECT_EQ(merged.records(), a.records() + b.records());
    PCG32 rng(3, 9);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 p(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        Vec3 d(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        d = d / norm(d);
        const uint32_t la = a.leaf_at(p), lb = b.leaf_at(p), lm = merged.leaf_at(p);
        const double ea = a.sampling(la).total(), eb = b.sampling(lb).total();
        ASSERT_NEAR(merged.sampling(lm).total(), ea + eb, 1e-9 * (ea + eb));
        const double want = (ea * a.pdf(la, d) + eb * b.pdf(lb, d)) / (ea + eb);
        ASSERT_NEAR(merged.pdf(lm, d), want, 1e-4 * want + 1e-7) << i;
    }
    const SDTree *one[] = {&a};
    const SDTree alone = SDTree::merge(one);
    // Alone, the same leaves and densities (its nodes may be numbered otherwise).
    EXPECT_EQ(alone.leaf_count(), a.leaf_count());
    for (int i = 0; i < 2000; ++i) {
        const Vec3 p(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        Vec3 d(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
        d = d / norm(d);
        ASSERT_EQ(alone.pdf(alone.leaf_at(p), d), a.pdf(a.leaf_at(p), d));
    }
    EXPECT_TRUE(SDTree::merge(both) == merged);
    BBox other;
    other.expand(Vec3(0.f));
    other.expand(Vec3(5.f));
    const SDTree c(other);
    const SDTree *mismatched[] = {&a, &c};
    EXPECT_THROW(SDTree::merge(mismatched), std::runtime_error);
}

}  // namespace
