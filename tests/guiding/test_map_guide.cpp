// The visibility map's guide: its directions follow its solid-angle density (chi-square on the sphere, the
// density integrating to one), from inside a voxel it may choose and from near the grid's edge; it guides
// toward the cells flux came from, and with the map's prior toward what the map says is visible; the guide
// a pass leaves depends on what was recorded, not on the order or the threads; its state saves, loads and
// merges exactly.
#include <gtest/gtest.h>
#include <algorithm>
#include <random>
#include <thread>
#include "common/chi2.h"
#include "neepp/guiding/map_guide.h"
#include "neepp/sampling/rng.h"
#include "neepp/visibility/visibility_map.h"

using namespace neepp;

namespace {

VoxelGrid grid4() {
    BBox b;
    b.expand(Vec3(-1.f, -1.f, -2.f));
    b.expand(Vec3(1.f, 3.f, 2.f));
    return VoxelGrid::with_exact_bounds(b, 4);
}

struct Record {
    Vec3 p;
    uint32_t target;
    double flux, radiance;
    Vec3 end;
};

// A point in the bottom tenth (along y) of voxel j: end points on a "floor", so target boxes are slabs.
Vec3 floor_point(const VoxelGrid &g, uint32_t j, PCG32 &rng) {
    int x, y, z;
    g.voxel_coords(j, x, y, z);
    const Vec3 cell = g.bounds().extent() / float(g.resolution());
    return g.bounds().lo + Vec3(float(x) + rng.next_float(), float(y) + 0.1f * rng.next_float(), float(z) + rng.next_float()) * cell;
}

// Records at points all over the grid, whose flux comes from a few voxels and direction bins (and some
// from anywhere); values are multiples of 1/8, exact in the guide's fixed point and its sums.
std::vector<Record> records(const VoxelGrid &g, uint64_t seed, int n) {
    PCG32 rng(seed, 3);
    const uint32_t favourites[] = {5, 17, 42, 63, g.voxel_count() + 3, g.voxel_count() + 50};
    std::vector<Record> out;
    const BBox &b = g.bounds();
    for (int i = 0; i < n; ++i) {
        Record r;
        r.p = b.lo + b.extent() * Vec3(rng.next_float(), rng.next_float(), rng.next_float());
        r.target = rng.next_float() < 0.8f ? favourites[rng.next_u32() % 6] : rng.next_u32() % g.cell_count();
        if (rng.next_float() < 0.05f) r.target = MapGuide::kNoTarget;
        r.flux = double(1 + rng.next_u32() % 32) / 8;
        r.radiance = double(1 + rng.next_u32() % 8) / 8;
        r.end = r.target < g.voxel_count() ? floor_point(g, r.target, rng) : Vec3(0.f);
        out.push_back(r);
    }
    return out;
}

MapGuide trained(const std::vector<Record> &rs, int passes, const VisibilityMap *map = nullptr) {
    MapGuide guide(grid4());
    for (int pass = 0; pass < passes; ++pass) {
        for (const Record &r : rs) guide.record(r.p, r.target, r.flux, r.radiance, r.end);
        guide.update(map);
    }
    return guide;
}

TEST(MapGuide, NothingRecordedNothingGuided) {
    MapGuide guide(grid4());
    guide.update(nullptr);
    EXPECT_EQ(guide.table_at(Vec3(0.f)), nullptr);
    EXPECT_EQ(guide.table_count(), 0u);
}

TEST(MapGuide, GuidesTowardTheCellsFluxCameFrom) {
    const VoxelGrid g = grid4();
    MapGuide guide(g);
    const Vec3 p(-0.9f, -0.9f, -1.9f);  // voxel 0
    for (int i = 0; i < 100; ++i) guide.record(p, 21, 3.0, 1.0, Vec3(0.f));
    for (int i = 0; i < 100; ++i) guide.record(p, g.voxel_count() + 7, 1.0, 1.0, Vec3(0.f));
    guide.update(nullptr);
    const MapGuide::Table *t = guide.table_at(p);
    ASSERT_NE(t, nullptr);
    EXPECT_NEAR(t->pmf[21], 0.75f, 1e-6f);
    EXPECT_NEAR(t->pmf[g.voxel_count() + 7], 0.25f, 1e-6f);
    EXPECT_EQ(t->cells.size(), 2u);
    EXPECT_EQ(guide.table_at(Vec3(0.9f, 2.9f, 1.9f)), nullptr) << "a voxel that recorded nothing";
    // The map's prior: voxel 1 recorded a sample that found nothing, so it learned only that cells 21 and
    // the bin shine; of those, the map says it sees only the bin.
    VisibilityMap map(g.cell_count());
    map.add(1, 21, 0, 1000);
    map.add(1, g.voxel_count() + 7, 1000, 1000);
    guide.record(Vec3(-0.4f, -0.9f, -1.9f), MapGuide::kNoTarget, 0, 0, Vec3(0.f));
    guide.update(&map);
    const MapGuide::Table *t1 = guide.table_at(Vec3(-0.4f, -0.9f, -1.9f));
    ASSERT_NE(t1, nullptr);
    EXPECT_GT(t1->pmf[g.voxel_count() + 7], 0.99f);
    EXPECT_LT(t1->pmf[21], 0.01f);
}

// Chi-square of directions against the guide's density, binned on the cube map that the direction bins
// are patches of (6 faces x R x R cells, each bin's patch R/4 x R/4 of them): the bins' part of the density
// is then constant in each cell's face coordinates, so only the voxels' part (whose silhouettes Simpson's
// rule integrates poorly) needs integrating, done by jittered Monte Carlo, 256 points a cell (64 left thin
// target boxes seen edge-on under-resolved: the integral 0.3 % off). `stretch` < 1 draws the point in a
// target box from only part of it along x (a wrong sampler, which the test must see).
test::Chi2Result chi2_on_cube_map(const MapGuide &guide, const MapGuide::Table &t, const Vec3 &p, uint64_t seed,
                                  float stretch = 1.f) {
    constexpr int R = 32, kJitter = 16;
    const int samples = 600000;
    // The direction through face coordinates (u, v) in [-1, 1]^2 of `face` (VoxelGrid's order), and the
    // solid angle per unit face area there (1 / r^3, r the distance to the face point).
    auto direction = [](int face, float u, float v) {
        const float s = face % 2 == 0 ? 1.f : -1.f;
        return face / 2 == 0 ? Vec3(s, u, v) : face / 2 == 1 ? Vec3(u, s, v) : Vec3(u, v, s);
    };
    auto cell_of = [&](const Vec3 &d) {
        const float ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
        int face;
        float u, v, m;
        if (ax >= ay && ax >= az) { face = d.x >= 0 ? 0 : 1; m = ax; u = d.y; v = d.z; }
        else if (ay >= az) { face = d.y >= 0 ? 2 : 3; m = ay; u = d.x; v = d.z; }
        else { face = d.z >= 0 ? 4 : 5; m = az; u = d.x; v = d.y; }
        auto bin = [&](float x) { return std::clamp(int((x / m * 0.5f + 0.5f) * R), 0, R - 1); };
        return size_t(face * R * R + bin(u) * R + bin(v));
    };
    std::vector<double> observed(6 * R * R, 0.0), expected(6 * R * R, 0.0);
    PCG32 rng(seed, 1);
    for (int i = 0; i < samples; ++i) {
        const float u0 = rng.next_float(), u1 = std::min(rng.next_float() * stretch, 0.999999f);
        const Vec3 d = guide.sample(t, p, u0, u1, rng.next_2d());
        if (squared_norm(d) > 0) observed[cell_of(d)] += 1;
    }
    const double cell_area = (2.0 / R) * (2.0 / R) / (kJitter * kJitter);
    for (int face = 0; face < 6; ++face)
        for (int iu = 0; iu < R; ++iu)
            for (int iv = 0; iv < R; ++iv) {
                double mass = 0;
                for (int a = 0; a < kJitter; ++a)
                    for (int b = 0; b < kJitter; ++b) {
                        const float u = -1.f + 2.f * (float(iu) + (float(a) + rng.next_float()) / kJitter) / R;
                        const float v = -1.f + 2.f * (float(iv) + (float(b) + rng.next_float()) / kJitter) / R;
                        const Vec3 w = direction(face, u, v);
                        const double r = double(norm(w));
                        mass += double(guide.pdf(t, p, w / float(r))) * cell_area / (r * r * r);
                    }
                expected[size_t(face * R * R + iu * R + iv)] = mass * samples;
            }
    test::Chi2Result res = test::chi2_from_histograms(observed, expected);
    double total = 0;
    for (double e : expected) total += e;
    res.pdf_integral = total / samples;
    return res;
}

// From a point inside a voxel the table gives weight to (the ray starts inside that box), and from a
// point near the grid's corner; the density integrates to one.
TEST(MapGuide, ChiSquareOfDirectionsAgainstSolidAngleDensity) {
    const VoxelGrid g = grid4();
    const Vec3 points[] = {Vec3(-0.3f, 0.2f, -0.6f), Vec3(0.95f, -0.97f, 1.9f)};
    std::vector<Record> rs = records(g, 1, 20000);
    for (const Vec3 &p : points)
        for (int i = 0; i < 20; ++i) rs.push_back({p, g.voxel_of(p), 2.0, 1.0, p});  // light from their own voxels
    const MapGuide guide = trained(rs, 2);
    int seed = 0;
    for (const Vec3 &p : points) {
        const MapGuide::Table *t = guide.table_at(p);
        ASSERT_NE(t, nullptr);
        EXPECT_GT(t->pmf[g.voxel_of(p)], 0.f) << "the point's own voxel is a target";
        const test::Chi2Result r = chi2_on_cube_map(guide, *t, p, 11 + seed++);
        EXPECT_TRUE(r.error.empty()) << r.error;
        EXPECT_NEAR(r.pdf_integral, 1.0, 3e-3) << r.describe();
        EXPECT_GT(r.p_value, 0.01 / 2) << r.describe();
    }
}

TEST(MapGuide, ChiSquareSeesAWrongDensity) {
    const VoxelGrid g = grid4();
    const MapGuide guide = trained(records(g, 2, 20000), 2);
    const Vec3 p(-0.3f, 0.2f, -0.6f);
    const MapGuide::Table *t = guide.table_at(p);
    ASSERT_NE(t, nullptr);
    // Points in a voxel drawn from only its lower four fifths along x: a density that no longer matches.
    const test::Chi2Result r = chi2_on_cube_map(guide, *t, p, 5, 0.8f);
    EXPECT_LT(r.p_value, 1e-6) << r.describe();
}

TEST(MapGuide, SameRecordsInAnyOrderMakeTheSameGuide) {
    const VoxelGrid g = grid4();
    const std::vector<Record> rs = records(g, 3, 30000);
    const MapGuide a = trained(rs, 3);
    std::vector<Record> shuffled = rs;
    std::mt19937 gen(1);
    std::shuffle(shuffled.begin(), shuffled.end(), gen);
    EXPECT_EQ(trained(shuffled, 3).save(), a.save());
    MapGuide c(g);
    for (int pass = 0; pass < 3; ++pass) {
        std::vector<std::thread> threads;
        for (int k = 0; k < 4; ++k)
            threads.emplace_back([&, k] {
                for (size_t i = k; i < shuffled.size(); i += 4)
                    c.record(shuffled[i].p, shuffled[i].target, shuffled[i].flux, shuffled[i].radiance, shuffled[i].end);
            });
        for (auto &th : threads) th.join();
        c.update(nullptr);
    }
    EXPECT_EQ(c.save(), a.save()) << "from four threads at once";
    MapGuide d(g);
    for (int pass = 0; pass < 3; ++pass) {
        for (const Record &r : rs) d.record(r.p, r.target, r.flux, r.radiance, r.end);
        if (pass == 2) d.record(rs[0].p, rs[0].target, rs[0].flux, rs[0].radiance, rs[0].end);
        d.update(nullptr);
    }
    EXPECT_NE(d.save(), a.save()) << "one record more";
}

TEST(MapGuide, SavesLoadsAndMergesExactly) {
    const VoxelGrid g = grid4();
    const std::vector<Record> base_records = records(g, 4, 5000), ra = records(g, 5, 4000), rb = records(g, 6, 3000);
    const MapGuide base = trained(base_records, 1);
    MapGuide b(g);
    b.load(base.save());
    b.update(nullptr);
    EXPECT_EQ(b.save(), base.save());
    const Vec3 p(0.1f, 0.1f, 0.1f);
    ASSERT_NE(b.table_at(p), nullptr);
    EXPECT_EQ(b.table_at(p)->pmf, base.table_at(p)->pmf) << "the loaded totals make the same tables";
    // Two renders from the base, each adding its records; merged, as one that recorded both.
    auto from_base = [&](const std::vector<Record> &rs) {
        MapGuide m(g);
        m.load(base.save());
        for (const Record &r : rs) m.record(r.p, r.target, r.flux, r.radiance, r.end);
        m.update(nullptr);
        return m.save();
    };
    const std::string states[] = {from_base(ra), from_base(rb)};
    MapGuide both(g);
    both.load(base.save());
    for (const auto *rs : {&ra, &rb})
        for (const Record &r : *rs) both.record(r.p, r.target, r.flux, r.radiance, r.end);
    both.update(nullptr);
    MapGuide merged(g);
    merged.load(MapGuide::merge(base.save(), states));
    merged.update(nullptr);
    EXPECT_EQ(merged.table_at(p)->pmf, both.table_at(p)->pmf);
    EXPECT_EQ(merged.records(), both.records());
    EXPECT_EQ(MapGuide::merge(base.save(), {}), base.save());
    // Malformed or another grid's.
    EXPECT_THROW(b.load(base.save().substr(0, 40)), std::runtime_error);
    EXPECT_THROW(b.load("not a guide"), std::runtime_error);
    BBox other;
    other.expand(Vec3(0.f));
    other.expand(Vec3(5.f));
    MapGuide elsewhere(VoxelGrid::with_exact_bounds(other, 4));
    EXPECT_THROW(elsewhere.load(base.save()), std::runtime_error);
}

}  // namespace
