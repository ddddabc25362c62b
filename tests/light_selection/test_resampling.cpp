// Resampled NEE (light_selection/resampling.h, PathIntegrator with ris = M): the proportional choice and
// the map's share of the target; at a fixed shading point, lit by area lights (one behind a wall), a
// point light and an environment, the resampled estimate's mean is plain NEE's, with the visibility map
// right and with a map that calls every pair occluded (Ṽ = floor where the truth is visible), while a
// right map lowers its variance; and renders agree with plain NEE (z-tests on the image mean and coarse
// blocks over independent seeds, as the NEE++ policy tests do) on an environment through a window, an
// area light through a door, the 30-light office, and through the door with a wrong map.
#include <gtest/gtest.h>
#include <cmath>
#include <filesystem>
#include <map>
#include "neepp/integrators/path.h"
#include "neepp/light_selection/resampling.h"
#include "neepp/sampling/rng.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/map_file.h"
#include "neepp/visibility/neepp_shadow_rays.h"
#include "common/seeded_map.h"
#include "test_scenes.h"
#include "visibility/visibility_test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// ---- The choice and the target ----------------------------------------------------------------------

TEST(Resampling, ChoosesInProportionToTheWeights) {
    const float w[5] = {1.f, 0.f, 3.f, 0.5f, 1.5f};
    std::vector<int> counts(5, 0);
    PCG32 rng(3, 1);
    const int n = 200000;
    for (int k = 0; k < n; ++k) {
        float sum = 0;
        const int i = choose_proportional(w, 5, rng.next_float(), sum);
        ASSERT_EQ(sum, 6.f);
        ASSERT_GE(i, 0);
        ++counts[size_t(i)];
    }
    EXPECT_EQ(counts[1], 0) << "a weight of 0 is never chosen";
    for (int i : {0, 2, 3, 4}) {
        const double p = w[i] / 6.0, sigma = std::sqrt(n * p * (1 - p));
        EXPECT_NEAR(counts[size_t(i)], n * p, 5 * sigma) << "candidate " << i;
    }
}

TEST(Resampling, NothingToChooseFromAndTheEdges) {
    float sum = 1;
    const float zeros[3] = {0.f, 0.f, 0.f};
    EXPECT_EQ(choose_proportional(zeros, 3, 0.5f, sum), -1);
    EXPECT_EQ(sum, 0.f);
    const float inf[2] = {1.f, INFINITY};
    EXPECT_EQ(choose_proportional(inf, 2, 0.5f, sum), -1);
    // u just below 1 takes the last positive weight, never a zero one after it.
    const float tail[4] = {1.f, 2.f, 1.f, 0.f};
    EXPECT_EQ(choose_proportional(tail, 4, 0x1.fffffep-1f, sum), 2);
    EXPECT_EQ(choose_proportional(tail, 4, 0.f, sum), 0);
}

TEST(Resampling, TargetVisibilityIsTheRootOfTheMapsEstimateAboveTheFloor) {
    const VoxelGrid grid(BBox{Vec3(0.f), Vec3(1.f)}, 4);
    VisibilityMap map(grid.cell_count());
    map.set(1, 2, PairCounts{0, 398});  // Ṽ = 1/400, √Ṽ = 0.05: below the floor
    map.set(1, 3, PairCounts{48, 98});  // Ṽ = 0.49
    map.set(5, 5, PairCounts{0, 98});   // a cell with itself: the map cannot tell
    const ResamplingVisibility v(&grid, &map, 0.1f);
    EXPECT_TRUE(v.uses_map());
    EXPECT_FLOAT_EQ(v(1, 2), 0.1f);
    EXPECT_FLOAT_EQ(v(2, 1), 0.1f);
    EXPECT_FLOAT_EQ(v(1, 3), 0.7f);
    EXPECT_EQ(v(1, 4), 1.f) << "never traced: visible";
    EXPECT_EQ(v(5, 5), 1.f) << "same cell: visible";
    const ResamplingVisibility none(&grid, nullptr, 0.05f);
    EXPECT_FALSE(none.uses_map());
    EXPECT_EQ(none(1, 2), 1.f);
    const VisibilityMap unseeded;
    EXPECT_FALSE(ResamplingVisibility(&grid, &unseeded, 0.05f).uses_map());
}

// ---- One shading point ------------------------------------------------------------------------------

// A glossy floor point at (-1, 0, 0), seen by the camera; a wall at x = 0.5 hides the bright panel
// above x = 1.5 from it, and part of the sky. A dimmer panel and a point light above it are visible.
std::string lit_point_xml() {
    return scene_header_xml(2, 30, "-1,1.2,1.6", "-1,0,0", 8, 8) + R"(
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="roughplastic"><float name="alpha" value="0.25"/><rgb name="diffuse_reflectance" value="0.5,0.4,0.3"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.05" y="1" z="3"/><translate x="0.5" y="1"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="90"/><translate x="1.5" y="1.5"/></transform>
    <ref id="white"/><emitter type="area"><rgb name="radiance" value="80"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.2"/><rotate x="1" angle="90"/><translate x="-1.6" y="1.4" z="-0.3"/></transform>
    <ref id="white"/><emitter type="area"><rgb name="radiance" value="6"/></emitter></shape>
  <emitter type="point"><point name="position" x="-0.6" y="1.2" z="0.8"/><rgb name="intensity" value="0.8"/></emitter>
  <emitter type="constant"><rgb name="radiance" value="0.4"/></emitter>
</scene>
)";
}

enum class Map { Built, ClaimsOccluded };

struct PointEstimate {
    double mean = 0, var = 0;  // of the luminance of one estimate
    int n = 0;
};

// n estimates of the light reflected at the point toward the camera (max_depth 2: direct light, NEE and
// BSDF sampling MIS-combined; the emitters the camera sees hidden), each with its own numbers.
PointEstimate estimate_at_point(const OptionMap &options, Map setup, int n) {
    auto scene = load_scene(write_temp_scene(lit_point_xml()));
    OptionMap o = options;
    o["max_depth"] = "2";
    o["hide_emitters"] = "true";
    auto integ = make_integrator("path", Options(o));
    auto *path = dynamic_cast<PathIntegrator *>(integ.get());
    if (setup == Map::ClaimsOccluded) {
        auto *tester = dynamic_cast<NeeppShadowRays *>(&path->shadow_rays());
        EXPECT_NE(tester, nullptr);
        VoxelGrid grid(scene->bounds(), tester->options().voxels);
        VisibilityMap map(grid.cell_count());
        for (uint64_t p = 0; p < map.pair_count(); ++p) map.set(p, PairCounts{0, 65535});
        tester->adopt_map(grid, std::move(map));
    }
    integ->prepare(*scene);
    const Ray ray{Vec3(-1.f, 1.2f, 1.6f), normalize(Vec3(0.f, -1.2f, -1.6f))};
    auto sampler = make_sampler("independent", 11);
    RenderCounters counters;
    double s = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
        sampler->start_sample(0, 0, uint32_t(i));
        const double l = luminance(dynamic_cast<const RayIntegrator &>(*integ).Li(*scene, ray, *sampler, counters));
        s += l;
        s2 += l * l;
    }
    PointEstimate e;
    e.n = n;
    e.mean = s / n;
    e.var = std::max(0.0, s2 / n - e.mean * e.mean);
    return e;
}

void expect_same_mean(const PointEstimate &ref, const PointEstimate &test, const std::string &what) {
    const double se = std::sqrt(ref.var / ref.n + test.var / test.n);
    EXPECT_GT(ref.mean, 1e-2) << "the point must be lit";
    EXPECT_LT(std::abs(test.mean - ref.mean), 5 * se)
        << what << ": plain NEE " << ref.mean << ", resampled " << test.mean << " (standard error " << se << ")";
}

constexpr int kTrials = 40000;

const PointEstimate &plain_nee_at_point() {
    static const PointEstimate e = estimate_at_point({}, Map::Built, kTrials);
    return e;
}

TEST(ResampledNeeAtAPoint, HasPlainNeesMeanAndLessVarianceWithARightMap) {
    for (const std::string &sampler : {"bvh", "power"}) {
        const PointEstimate nee = estimate_at_point({{"light_sampler", sampler}}, Map::Built, kTrials);
        const PointEstimate ris = estimate_at_point({{"ris", "8"}, {"light_sampler", sampler}}, Map::Built, kTrials);
        expect_same_mean(plain_nee_at_point(), ris, "ris=8, " + sampler);
        // The panel behind the wall outweighs the others by power and by the BVH's bounds; resampling by
        // f·Le·Ṽ moves the samples to the lights that reach the point.
        EXPECT_LT(ris.var, 0.8 * nee.var) << sampler;
    }
    // With a shadow-ray policy that plays roulette on the chosen sample's ray.
    expect_same_mean(plain_nee_at_point(), estimate_at_point({{"ris", "4"}, {"shadow_rays", "neepp"}}, Map::Built, kTrials),
                     "ris=4, neepp");
}

TEST(ResampledNeeAtAPoint, StaysUnbiasedWhenTheMapClaimsEverythingOccluded) {
    // Ṽ = 1.5e-5 for every pair, so the floor is every candidate's visibility: visible ones included.
    for (const std::string &floor : {"0.01", "0.2"}) {
        const PointEstimate ris = estimate_at_point({{"ris", "8"}, {"ris_floor", floor}}, Map::ClaimsOccluded, kTrials);
        expect_same_mean(plain_nee_at_point(), ris, "ris=8 with a wrong map, floor " + floor);
    }
}

// ---- Renders ---------------------------------------------------------------------------------------

constexpr int kSeeds = 6;

// An integrator with a map reads the one the scene's first render seeded (common/seeded_map.h).
BlockMoments render_moments(const std::string &path, const OptionMap &options, int spp, uint64_t seed0) {
    std::vector<std::vector<double>> per_seed;
    const Options o(with_map_file(options, map_file_beside(path)));
    for (int s = 0; s < kSeeds; ++s)
        per_seed.push_back(block_means(render_scene_file(path, spp, seed0 + uint64_t(s) * 7919, o).image, 6, 6));
    return moments_over_seeds(per_seed);
}

const std::string &two_rooms() {
    static const std::string p = write_temp_scene(two_rooms_xml(false), "rooms.xml");
    return p;
}

const BlockMoments &nee_through_the_door() {
    static const BlockMoments m = render_moments(two_rooms(), {}, 64, 101);
    return m;
}

TEST(ResampledNeeRender, AgreesWithNeeForAnEnvironmentThroughAWindow) {
    const std::string path = write_temp_scene(window_room_xml(), "window.xml");
    const BlockMoments nee = render_moments(path, {}, 32, 101);
    expect_same_image(nee, render_moments(path, {{"ris", "8"}, {"ris_depth", "-1"}}, 32, 5003),
                      "ris=8 at every vertex, window");
}

TEST(ResampledNeeRender, AgreesWithNeeThroughADoor) {
    expect_same_image(nee_through_the_door(), render_moments(two_rooms(), {{"ris", "8"}, {"ris_depth", "-1"}}, 64, 5003),
                      "ris=8 at every vertex, two rooms");
    expect_same_image(nee_through_the_door(),
                      render_moments(two_rooms(), {{"ris", "4"}, {"shadow_rays", "neepp-adaptive"}}, 64, 7001),
                      "ris=4 + neepp-adaptive, two rooms");
}

TEST(ResampledNeeRender, AgreesWithNeeOnTheOffice) {
    // 30 lights, most behind walls; a small crop of the project scene.
    const std::string path = std::string(NEEPP_SOURCE_DIR) + "/scenes/office/scene.xml";
    // The renders with a map start from the one the first seeded (common/seeded_map.h), in a folder of the test's.
    const std::string map_file = map_file_beside(write_temp_scene("", "office.txt"), "office.map");
    auto moments = [&](const OptionMap &o, uint64_t seed0) {
        std::vector<std::vector<double>> per_seed;
        for (int s = 0; s < kSeeds; ++s) {
            auto scene = load_scene(path, {{"resx", "36"}, {"resy", "24"}, {"max_depth", "4"}});
            Options options(with_map_file(o, map_file));
            for (auto &[k, v] : scene->settings.integrator_options)
                if (!options.has(k)) options.set(k, v);
            auto integ = make_integrator("path", options);
            RenderJob job;
            job.spp = 16;
            job.seed = seed0 + uint64_t(s) * 7919;
            per_seed.push_back(block_means(render(*scene, *integ, job).image, 6, 6));
        }
        return moments_over_seeds(per_seed);
    };
    const BlockMoments nee = moments({}, 101);
    expect_same_image(nee, moments({{"ris", "8"}}, 5003), "ris=8, office");
    expect_same_image(nee, moments({{"ris", "4"}, {"ris_depth", "-1"}}, 7001), "ris=4 at every vertex, office");
    expect_same_image(nee, moments({{"ris", "8"}, {"light_sampler", "visibility"}}, 9001), "ris=8 + visibility, office");
}

TEST(ResampledNeeRender, AWrongMapCostsVarianceNotBias) {
    // The map of the rooms with the door closed, frozen (no learning): the door pairs are seen occluded.
    const std::string path = two_rooms();
    const std::string map_file = (std::filesystem::path(path).parent_path() / "closed.map").string();
    {
        auto open = load_scene(path);
        auto closed = load_scene(write_temp_scene(two_rooms_xml(true), "closed.xml"));
        NeeppOptions o;
        o.policy = ShadowRayPolicy::TraceAll;
        NeeppShadowRays seeder(o);
        seeder.prepare(*closed);
        // The open scene's fingerprint, so the render takes the closed door's map as its own.
        save_visibility_map(map_file, seeder.grid(), seeder.map(), scene_fingerprint(*open));
    }
    expect_same_image(nee_through_the_door(),
                      render_moments(path, {{"ris", "8"}, {"ris_depth", "-1"}, {"visibility_map", map_file}, {"learn", "false"}}, 64, 9001),
                      "ris=8, map from the closed door");
}

}  // namespace
