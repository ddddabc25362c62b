// NEE++ inside an environment map (VisibilityEnvironmentSampler): its directions follow its density
// (chi-square over the sphere, the density integrating to one), a sample's density is what pdf() says of
// it, the density is positive wherever the map's own is (whatever the visibility map says), the map's
// verdicts move probability between direction groups as the rule says, and a render with it agrees
// with plain NEE (z-tests over seeds) while tracing fewer occluded shadow rays, with a right map and
// with a deliberately wrong one.
#include <gtest/gtest.h>
#include <cmath>
#include <filesystem>
#include "common/chi2.h"
#include "neepp/io/image.h"
#include "neepp/light_selection/visibility_environment.h"
#include "neepp/sampling/rng.h"
#include "neepp/visibility/map_file.h"
#include "neepp/visibility/neepp_shadow_rays.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;
using neepp::test::Chi2Result;
using neepp::test::SphereChi2Config;

namespace {

// A sky: a smooth gradient, brighter toward +v's top, and a small bright sun.
Image sky_image(int w = 64, int h = 32) {
    Image img(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float base = 0.2f + 0.8f * float(h - y) / float(h) + 0.1f * std::sin(float(x) * 0.3f);
            for (int c = 0; c < 3; ++c) img.at(x, y, c) = base * (1.f - 0.2f * float(c));
        }
    for (int y = 6; y <= 7; ++y)
        for (int x = 40; x <= 41; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y, c) = 200.f;
    return img;
}

struct Fixture {
    EnvironmentMapLight env{sky_image(), Transform::rotate(Vec3(0.3f, 1.f, 0.2f), 25.f), 1.f};
    VoxelGrid grid{BBox{Vec3(-1.f), Vec3(1.f)}, 4};
    VisibilityMap map{grid.cell_count()};
    Vec3 p{0.1f, -0.2f, 0.3f};
    uint32_t voxel = grid.voxel_of(p);
    // The voxel sees the bins of +y's face fully, half of -x's, and none of the others (16 rays each).
    Fixture() {
        for (uint32_t b = 0; b < VoxelGrid::kDirectionBins; ++b) {
            const uint32_t face = b / (VoxelGrid::kDirectionBinsPerFaceSide * VoxelGrid::kDirectionBinsPerFaceSide);
            const uint16_t visible = face == 2 ? 16 : face == 1 ? 8 : 0;
            map.set(voxel, grid.voxel_count() + b, PairCounts{visible, 16});
        }
    }
};

SphereChi2Config sphere() {
    SphereChi2Config cfg;
    cfg.res = 48;
    cfg.ires = 16;
    cfg.sample_count = 400000;
    return cfg;
}

TEST(VisibilityEnvironment, DirectionsFollowPdfWhichIntegratesToOne) {
    Fixture f;
    VisibilityEnvironmentSampler s(f.env, f.grid, f.map);
    for (const Vec3 n : {Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, 0, 0)}) {
        const LightSampleContext ctx{f.p, n};
        Chi2Result r = neepp::test::chi2_sphere_test(
            [&](PCG32 &rng) -> std::optional<Vec3> {
                Color L;
                const DirectionSample ds = s.sample(ctx, Vec2(rng.next_float(), rng.next_float()), L);
                if (!(ds.pdf > 0)) return std::nullopt;
                return ds.d;
            },
            [&](const Vec3 &d) { return double(s.pdf(ctx, direction_sample_from_miss(d))); }, sphere());
        ASSERT_TRUE(r.error.empty()) << r.describe();
        EXPECT_GT(r.p_value, 1e-4) << r.describe();
        EXPECT_NEAR(r.pdf_integral, 1.0, 3e-3) << r.describe();
        EXPECT_EQ(r.valid_fraction, 1.0);
    }
}

TEST(VisibilityEnvironment, SampleReportsThePdfAndRadianceAskedAfterwards) {
    Fixture f;
    VisibilityEnvironmentSampler s(f.env, f.grid, f.map);
    const LightSampleContext ctx{f.p, Vec3(0, 1, 0)};
    PCG32 rng(7, 1);
    int mismatched = 0;
    constexpr int kCount = 20000;
    for (int i = 0; i < kCount; ++i) {
        Color L;
        const DirectionSample ds = s.sample(ctx, Vec2(rng.next_float(), rng.next_float()), L);
        ASSERT_GT(ds.pdf, 0.f);
        const float pdf = s.pdf(ctx, direction_sample_from_miss(ds.d));
        // A sample on a cell's edge may round into its neighbour when its direction is turned back into uv.
        if (std::abs(pdf - ds.pdf) > 1e-3f * ds.pdf) ++mismatched;
        const Color E = f.env.eval_environment(ds.d);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(L[c], E[c], 1e-3f * std::max(1.f, E[c]));
        // The sampled direction's step API gives the same sample.
        Color L2;
        const DirectionSample again = s.finish(ctx, s.begin(ctx, Vec2(0.25f, 0.75f)), L2);
        const DirectionSample direct = s.sample(ctx, Vec2(0.25f, 0.75f), L2);
        EXPECT_EQ(again.pdf, direct.pdf);
    }
    EXPECT_LT(mismatched, kCount / 1000) << mismatched << " samples' pdf differs from pdf()";
}

TEST(VisibilityEnvironment, PositiveWhereverTheMapsOwnDensityIs) {
    Fixture f;
    VisibilityEnvironmentSampler s(f.env, f.grid, f.map);
    PCG32 rng(3, 1);
    for (int i = 0; i < 20000; ++i) {
        const Vec3 d = normalize(Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f));
        const DirectionSample ds = direction_sample_from_miss(d);
        if (f.env.pdf_direction(f.p, ds) > 0)
            for (const Vec3 n : {Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(1, 0, 0)})
                ASSERT_GT(s.pdf(LightSampleContext{f.p, n}, ds), 0.f) << "a direction the sky lights is never sampled";
    }
}

TEST(VisibilityEnvironment, GroupsTheMapSeesOccludedLoseProbability) {
    Fixture f;
    VisibilityEnvironmentSampler s(f.env, f.grid, f.map);
    const LightSampleContext ctx{f.p, Vec3(0, 0, 0)};  // no orientation: the map alone decides
    const std::vector<double> p = s.group_probabilities(ctx);
    // The groups' own masses: the share of the map's own samples that land in each.
    std::vector<double> mass(VisibilityEnvironmentSampler::kGroups, 0.0);
    PCG32 rng(11, 1);
    constexpr int kCount = 200000;
    for (int i = 0; i < kCount; ++i) {
        Color L;
        const DirectionSample ds = f.env.sample_direction(f.p, Vec2(rng.next_float(), rng.next_float()), L);
        mass[s.group_of(f.env.direction_to_uv(ds.d))] += 1.0 / kCount;
    }
    constexpr uint32_t kPerFace = VoxelGrid::kDirectionBinsPerFaceSide * VoxelGrid::kDirectionBinsPerFaceSide;
    double seen = 0, half = 0, occluded = 0, seen_mass = 0, half_mass = 0, occluded_mass = 0;
    for (uint32_t g = 0; g < VisibilityEnvironmentSampler::kGroups; ++g) {
        const uint32_t face = g / kPerFace;
        (face == 2 ? seen : face == 1 ? half : occluded) += p[g];
        (face == 2 ? seen_mass : face == 1 ? half_mass : occluded_mass) += mass[g];
        if (mass[g] > 0.01) EXPECT_GE(p[g], 0.1 * mass[g] * 0.9) << "group " << g << " lost its defensive share";
    }
    ASSERT_GT(seen_mass, 0.05);
    ASSERT_GT(half_mass, 0.02);
    // The rule: (1 − ε)·M·sqrt(ν) normalised, + ε·M, with ν = 1, 1/2 and 0 (floored at δ = 0.01).
    const double w_seen = seen_mass, w_half = half_mass * std::sqrt(0.5), w_occ = occluded_mass * 0.01;
    const double total = w_seen + w_half + w_occ;
    EXPECT_NEAR(seen, 0.9 * w_seen / total + 0.1 * seen_mass, 0.01);
    EXPECT_NEAR(half, 0.9 * w_half / total + 0.1 * half_mass, 0.01);
    EXPECT_NEAR(occluded, 0.9 * w_occ / total + 0.1 * occluded_mass, 0.01);
}

TEST(VisibilityEnvironment, FacingBucketsFavourTheHemisphereAboveTheSurface) {
    Fixture f;
    VisibilityMap open(f.grid.cell_count());  // nothing known: every group visible
    VisibilityEnvironmentSampler s(f.env, f.grid, open);
    PCG32 rng(5, 1);
    for (const Vec3 n : {Vec3(0, 1, 0), Vec3(0, 0, -1)}) {
        int above = 0;
        for (int i = 0; i < 20000; ++i) {
            Color L;
            above += dot(s.sample(LightSampleContext{f.p, n}, Vec2(rng.next_float(), rng.next_float()), L).d, n) > 0;
        }
        int own_above = 0;
        for (int i = 0; i < 20000; ++i) {
            Color L;
            own_above += dot(f.env.sample_direction(f.p, Vec2(rng.next_float(), rng.next_float()), L).d, n) > 0;
        }
        EXPECT_GT(above, own_above + 1000) << "normal " << n.x << "," << n.y << "," << n.z;
    }
}

TEST(VisibilityEnvironment, TablesFollowTheMapAfterEachPass) {
    Fixture f;
    VisibilityEnvironmentSampler s(f.env, f.grid, f.map);
    const LightSampleContext ctx{f.p, Vec3(0, 0, 0)};
    const uint32_t g = 2 * 16 + 5;  // a group of +y's face
    const double before = s.group_probabilities(ctx)[g];
    f.map.set(f.voxel, f.grid.voxel_count() + g, PairCounts{0, 200});
    EXPECT_EQ(s.group_probabilities(ctx)[g], before) << "tables are frozen for the pass";
    s.end_pass();
    EXPECT_LT(s.group_probabilities(ctx)[g], 0.5 * before);
}

// ---- Renders ------------------------------------------------------------------------------------------

// A floor under a low roof, lit by a sky with a sun the roof hides from most of the floor: most of the
// sky's own samples are occluded, and the visibility map learns which directions get under the roof.
std::string roofed_floor_scene() {
    static const std::string dir = [] {
        const auto d = std::filesystem::path(write_temp_scene("<scene version=\"3.0.0\"/>", "x.xml")).parent_path();
        write_exr((d / "sky.exr").string(), sky_image());
        return d.string();
    }();
    return write_temp_scene(scene_header_xml(3, 60, "0,0.5,3.2", "0,0.2,0", 24, 18) + R"(
  <bsdf type="twosided" id="grey"><bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale x="3" y="3"/><rotate x="1" angle="-90"/></transform><ref id="grey"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="2" y="2"/><rotate x="1" angle="90"/><translate y="0.6"/></transform><ref id="grey"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="2" y="0.3"/><translate y="0.3" z="-2"/></transform><ref id="grey"/></shape>
  <emitter type="envmap"><string name="filename" value=")" + dir + R"(/sky.exr"/></emitter>
</scene>
)", "roofed.xml");
}

struct EnvRun : BlockMoments {
    uint64_t shadow_rays = 0, occluded = 0;
};

EnvRun env_moments(const std::string &path, const OptionMap &options, uint64_t seed0) {
    std::vector<std::vector<double>> per_seed;
    EnvRun run;
    for (int s = 0; s < 6; ++s) {
        RenderedImage r = render_scene_file(path, 32, seed0 + uint64_t(s) * 7919, Options(options));
        run.shadow_rays += r.result.counters.shadow_rays;
        run.occluded += r.result.counters.shadow_rays_occluded;
        per_seed.push_back(block_means(r.image, 6, 6));
    }
    static_cast<BlockMoments &>(run) = moments_over_seeds(per_seed);
    return run;
}

TEST(VisibilityEnvironmentRender, AgreesWithPlainNeeAndWastesFewerShadowRays) {
    const std::string path = roofed_floor_scene();
    const EnvRun nee = env_moments(path, {}, 101);
    const EnvRun vis = env_moments(path, {{"within_light", "visibility"}}, 5003);
    expect_same_image(nee, vis, "within_light=visibility");
    const double f_nee = double(nee.occluded) / double(nee.shadow_rays), f_vis = double(vis.occluded) / double(vis.shadow_rays);
    EXPECT_LT(f_vis, 0.8 * f_nee) << "occluded fraction: nee " << f_nee << ", within_light=visibility " << f_vis;
    // With shadow-ray rejection on top, too.
    expect_same_image(nee, env_moments(path, {{"within_light", "visibility"}, {"shadow_rays", "neepp"}}, 9001),
                      "within_light=visibility + neepp");
}

TEST(VisibilityEnvironmentRender, AWrongMapCostsVarianceNotBias) {
    // A map that calls every direction occluded, frozen (no learning): the defensive share alone finds the sky.
    // Every voxel's pair with every direction bin is set: those are the only pairs sampling within an
    // environment light reads (VisibilityEnvironmentSampler::build), so this map renders to the bit what one
    // with all of the grid's 8.8 M pairs occluded renders, in a file of 3 MB rather than 70 MB (written once,
    // read by each of the six renders).
    const std::string path = roofed_floor_scene();
    const std::string map_file = std::filesystem::path(path).parent_path() / "wrong.map";
    {
        auto scene = load_scene(path);
        NeeppOptions o;
        o.policy = ShadowRayPolicy::TraceAll;
        NeeppShadowRays tester(o);
        tester.prepare(*scene);
        VisibilityMap &m = tester.mutable_map();
        const VoxelGrid &grid = tester.grid();
        for (uint32_t voxel = 0; voxel < grid.voxel_count(); ++voxel)
            for (uint32_t bin = 0; bin < uint32_t(VoxelGrid::kDirectionBins); ++bin)
                m.set(voxel, grid.voxel_count() + bin, PairCounts{0, 1000});
        save_visibility_map(map_file, tester.grid(), m, scene_fingerprint(*scene));
    }
    const EnvRun nee = env_moments(path, {}, 101);
    const EnvRun wrong = env_moments(path, {{"within_light", "visibility"}, {"visibility_map", map_file}, {"learn", "false"}}, 77);
    expect_same_image(nee, wrong, "within_light=visibility with a wrong map");
}

}  // namespace
