// NEE++ in the renderer: every policy converges to the image of plain NEE (z-tests on the image mean and
// coarse blocks over independent seeds, as in tests/integrators/test_nee_vs_bsdf.cpp) on hard-visibility
// scenes, including one where the map is badly wrong; renders are reproducible; neepp traces fewer rays.
#include <gtest/gtest.h>
#include <map>
#include "neepp/integrators/path.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/map_seeding.h"
#include "neepp/visibility/neepp_shadow_rays.h"
#include "test_scenes.h"
#include "visibility_test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// How the map is made before a render: built by prepare() (the normal case), or planted wrong.
enum class MapSetup { Built, ClaimsOccluded, FromClosedDoor };

struct PolicyRun {
    Image image;
    RenderCounters counters;
};

PolicyRun render_policy(const std::string &xml_path, const std::string &policy, int spp, uint64_t seed,
                  MapSetup setup = MapSetup::Built) {
    auto scene = load_scene(xml_path);
    Options o(OptionMap{{"shadow_rays", policy}});
    for (auto &[k, v] : scene->settings.integrator_options) o.set(k, v);
    auto integ = make_integrator("path", o);
    auto *path = dynamic_cast<PathIntegrator *>(integ.get());
    if (setup != MapSetup::Built) {
        auto *tester = dynamic_cast<NeeppShadowRays *>(&path->shadow_rays());
        EXPECT_NE(tester, nullptr);
        // Seeded with the door closed, rendered with it open: the door pairs were seen fully occluded.
        if (setup == MapSetup::ClaimsOccluded) plant_map_claiming_everything_occluded(*tester, *scene);
        else plant_map_seeded_on(*tester, *load_scene(write_temp_scene(two_rooms_xml(true))));
    }
    // neepp-cv's weight is negative for traced, occluded rays: this also checks that the render loop keeps
    // negative samples (dropping them would bias the image and fail the z-tests).
    RenderJob job;
    job.spp = spp;
    job.seed = seed;
    RenderResult r = render(*scene, *integ, job);
    return PolicyRun{r.image, r.counters};
}

struct Moments : BlockMoments {
    uint64_t shadow_rays = 0, skipped = 0;
};

Moments block_moments(const std::string &path, const std::string &policy, int seeds, int spp, uint64_t seed0,
                      MapSetup setup = MapSetup::Built) {
    std::vector<std::vector<double>> per_seed;
    Moments m;
    for (int s = 0; s < seeds; ++s) {
        PolicyRun run = render_policy(path, policy, spp, seed0 + uint64_t(s) * 7919, setup);
        m.shadow_rays += run.counters.shadow_rays;
        m.skipped += run.counters.shadow_rays_skipped;
        per_seed.push_back(block_means(run.image, 6, 6));
    }
    static_cast<BlockMoments &>(m) = moments_over_seeds(per_seed);
    return m;
}

constexpr int kSeeds = 6;

const Moments &nee_reference(const std::string &key, const std::string &path, int spp) {
    static std::map<std::string, Moments> cache;
    auto it = cache.find(key);
    if (it == cache.end()) it = cache.emplace(key, block_moments(path, "nee", kSeeds, spp, 101)).first;
    return it->second;
}

const std::string &two_rooms_path() {
    static std::string p = write_temp_scene(two_rooms_xml(false));
    return p;
}
const std::string &window_room_path() {
    static std::string p = write_temp_scene(window_room_xml());
    return p;
}

class PolicyTest : public ::testing::TestWithParam<std::string> {};

TEST_P(PolicyTest, AgreesWithNeeThroughADoor) {
    const Moments &nee = nee_reference("rooms", two_rooms_path(), 64);
    Moments pol = block_moments(two_rooms_path(), GetParam(), kSeeds, 64, 5003);
    expect_same_image(nee, pol, GetParam() + " two rooms");
    EXPECT_GT(pol.skipped, 0u) << "the policy never skipped a ray: the test would not exercise the roulette";
}

TEST_P(PolicyTest, StaysUnbiasedWhenTheMapClaimsEverythingOccluded) {
    const Moments &nee = nee_reference("rooms", two_rooms_path(), 64);
    Moments pol = block_moments(two_rooms_path(), GetParam(), kSeeds, 64, 7001, MapSetup::ClaimsOccluded);
    expect_same_image(nee, pol, GetParam() + " map claims occluded");
    EXPECT_GT(pol.skipped, 0u);
}

TEST_P(PolicyTest, StaysUnbiasedWithAMapSeededBehindAClosedDoor) {
    const Moments &nee = nee_reference("rooms", two_rooms_path(), 64);
    Moments pol = block_moments(two_rooms_path(), GetParam(), kSeeds, 64, 9001, MapSetup::FromClosedDoor);
    expect_same_image(nee, pol, GetParam() + " map from closed door");
    EXPECT_GT(pol.skipped, 0u);
}

TEST_P(PolicyTest, AgreesWithNeeForAnEnvironmentThroughAWindow) {
    const Moments &nee = nee_reference("window", window_room_path(), 32);
    Moments pol = block_moments(window_room_path(), GetParam(), kSeeds, 32, 11003);
    expect_same_image(nee, pol, GetParam() + " window");
    EXPECT_GT(pol.skipped, 0u);
}

INSTANTIATE_TEST_SUITE_P(Neepp, PolicyTest, ::testing::Values("neepp", "neepp-adaptive", "neepp-cv"), policy_test_name);

TEST(NeeppRender, TracesFewerShadowRaysThanNee) {
    PolicyRun nee = render_policy(two_rooms_path(), "nee", 16, 1);
    PolicyRun pp = render_policy(two_rooms_path(), "neepp", 16, 1);
    EXPECT_EQ(nee.counters.shadow_rays_skipped, 0u);
    EXPECT_LT(double(pp.counters.shadow_rays), 0.6 * double(nee.counters.shadow_rays))
        << "neepp " << pp.counters.shadow_rays << " nee " << nee.counters.shadow_rays;
    // Every NEE query is answered: traced or skipped (same sampling otherwise, so the totals are close).
    double queries = double(pp.counters.shadow_rays + pp.counters.shadow_rays_skipped);
    EXPECT_NEAR(queries / double(nee.counters.shadow_rays), 1.0, 0.05);
}

TEST(NeeppRender, ReproducibleForAGivenSeed) {
    for (std::string policy : {"neepp", "neepp-adaptive"}) {
        PolicyRun a = render_policy(two_rooms_path(), policy, 24, 77);
        PolicyRun b = render_policy(two_rooms_path(), policy, 24, 77);
        EXPECT_EQ(a.image.data, b.image.data) << policy << ": two renders with the same seed differ";
        EXPECT_EQ(a.counters.shadow_rays, b.counters.shadow_rays) << policy;
        EXPECT_EQ(a.counters.shadow_rays_skipped, b.counters.shadow_rays_skipped) << policy;
        PolicyRun c = render_policy(two_rooms_path(), policy, 24, 78);
        EXPECT_NE(a.image.data, c.image.data) << policy << ": the seed must matter";
    }
}

// A policy that says it does not read a query's contribution decides the same whatever the contribution
// (BDPT then works out its MIS weight only after the test), and the adaptive policy, which reads it, does not.
TEST(NeeppRender, ReadsTheContributionOnlyWhereItSaysSo) {
    for (std::string policy : {"nee", "neepp", "neepp-cv", "neepp-adaptive"}) {
        auto scene = load_scene(two_rooms_path());
        auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", policy}}));
        RenderJob job;
        job.spp = 8;
        render(*scene, *integ, job);  // the map seeded and learned, the adaptive scale calibrated
        const ShadowRayTester &tester = dynamic_cast<PathIntegrator &>(*integ).shadow_rays();
        const BBox b = scene->bounds();
        std::unique_ptr<Sampler> points = make_sampler("independent", 5);
        points->start_sample(0, 0, 0);
        int differ = 0;
        for (int i = 0; i < 2000; ++i) {
            auto point = [&] {
                return b.lo + Vec3(points->next_1d(), points->next_1d(), points->next_1d()) * b.extent();
            };
            ShadowQuery q;
            q.from = point();
            q.to = point();
            q.ray = Ray{q.from, normalize(q.to - q.from), 0.f, norm(q.to - q.from)};
            ShadowTest tests[2];
            for (int k = 0; k < 2; ++k) {
                q.unoccluded = Color(k == 0 ? 1e-4f : 10.f);
                std::unique_ptr<Sampler> sampler = make_sampler("independent", 9);
                sampler->start_sample(uint32_t(i), 0, 0);
                RenderCounters counters;
                tests[k] = tester.begin_test(q, *sampler, counters);
            }
            const bool same = tests[0].trace == tests[1].trace && tests[0].if_visible == tests[1].if_visible &&
                              tests[0].if_occluded == tests[1].if_occluded && tests[0].if_skipped == tests[1].if_skipped;
            if (!same) ++differ;
            if (!tester.reads_contribution()) ASSERT_TRUE(same) << policy << ": query " << i;
        }
        if (tester.reads_contribution()) EXPECT_GT(differ, 0) << policy << " says it reads the contribution";
        else EXPECT_EQ(differ, 0) << policy;
        EXPECT_EQ(tester.reads_contribution(), policy == "neepp-adaptive") << policy;
    }
}

// The efficiency target trades rays for variance by their cost: nearly free rays are (almost) all traced,
// expensive ones skipped more than the paper's rule would.
TEST(NeeppRender, AdaptiveEfficiencyFollowsTheShadowRayCost) {
    auto traced_fraction = [](const std::string &cost) {
        auto scene = load_scene(two_rooms_path());
        auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp-adaptive"}, {"shadow_ray_cost", cost},
                                                               {"max_depth", "4"}}));
        RenderJob job;
        job.spp = 16;
        RenderResult r = render(*scene, *integ, job);
        EXPECT_EQ(integ->describe()["shadow_ray_options"]["shadow_ray_cost"].get<float>(), std::stof(cost));
        return double(r.counters.shadow_rays) / double(r.counters.shadow_rays + r.counters.shadow_rays_skipped);
    };
    double cheap = traced_fraction("0.000001"), dear = traced_fraction("1");
    EXPECT_GT(cheap, 0.9) << "rays that cost nothing should nearly all be traced";
    EXPECT_LT(dear, cheap - 0.2) << "expensive rays should be skipped more";
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp-adaptive"}, {"shadow_ray_cost", "0"}})),
                 std::invalid_argument);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp-adaptive"}, {"adaptive_target", "speed"}})),
                 std::invalid_argument);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp"}, {"shadow_ray_cost", "0.1"}})),
                 std::invalid_argument);
}

TEST(NeeppRender, StatisticsDescribeTheMapAndTheRoulette) {
    auto scene = load_scene(two_rooms_path());
    auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp"}, {"voxels", "8"},
                                                           {"samples_per_pair", "4"}, {"q_min", "0.1"}, {"max_depth", "4"}}));
    RenderJob job;
    job.spp = 4;
    render(*scene, *integ, job);
    nlohmann::json d = integ->describe(), s = integ->statistics();
    EXPECT_EQ(d["shadow_rays"], "neepp");
    EXPECT_EQ(d["shadow_ray_options"]["voxels"], 8);
    EXPECT_EQ(d["shadow_ray_options"]["samples_per_pair"], 4);
    EXPECT_FLOAT_EQ(d["shadow_ray_options"]["q_min"].get<float>(), 0.1f);
    const auto &map = s["shadow_rays"]["map"];
    EXPECT_EQ(map["resolution"], 8);
    EXPECT_GT(map["occupied_voxels"].get<int>(), 10);
    EXPECT_GT(map["seeded_pairs"].get<int>(), 0);
    EXPECT_GT(map["build_shadow_rays"].get<int>(), 0);
    EXPECT_GT(map["memory_mb"].get<double>(), 0);
    EXPECT_GT(s["shadow_rays"]["roulette"]["skipped"].get<int>(), 0);
    EXPECT_GE(s["shadow_rays"]["roulette"]["mean_q"].get<double>(), 0.1);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"shadow_rays", "nee"}, {"voxels", "8"}})), std::invalid_argument);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"shadow_rays", "always"}})), std::invalid_argument);
}

}  // namespace

namespace {

// Renders the two rooms with neepp; of the pairs the seeding measured at least `at_least` times, returns
// how many there are and how many the render's online learning changed.
std::pair<int, int> seeded_pairs_changed_by_render(int learn_until, int at_least) {
    auto scene = load_scene(two_rooms_path());
    Options o(OptionMap{{"shadow_rays", "neepp"}, {"max_depth", "4"}, {"learn_until", std::to_string(learn_until)}});
    auto integ = make_integrator("path", o);
    auto &tester = dynamic_cast<NeeppShadowRays &>(dynamic_cast<PathIntegrator &>(*integ).shadow_rays());
    NeeppOptions seeding = tester.options();
    seeding.defer_seeding = false;
    NeeppShadowRays seeded(seeding);  // the same seeding (deferred in the render), kept to compare with
    seeded.prepare(*scene);
    RenderJob job;
    job.spp = 16;
    render(*scene, *integ, job);
    int measured = 0, changed = 0;
    for (uint64_t p = 0; p < seeded.map().pair_count(); ++p) {
        const PairCounts before = seeded.map().counts_at(p), after = tester.map().counts_at(p);
        if (before.traced == 0 || before.traced < at_least) continue;
        ++measured;
        changed += after.traced != before.traced || after.visible != before.visible;
    }
    return {measured, changed};
}

}  // namespace

// Pairs whose count has reached learn_until are no longer updated; below it, rendering keeps learning.
TEST(NeeppRender, LearningStopsAtLearnUntil) {
    const int per_pair = NeeppOptions{}.samples_per_pair;
    auto [measured, changed] = seeded_pairs_changed_by_render(NeeppOptions{}.learn_until, per_pair);
    EXPECT_GT(measured, 1000);
    EXPECT_GT(changed, measured / 50) << "below the cap, the render's shadow rays update the map";
    auto [measured_at_cap, changed_at_cap] = seeded_pairs_changed_by_render(per_pair, per_pair);
    EXPECT_EQ(measured_at_cap, measured);
    EXPECT_EQ(changed_at_cap, 0) << "pairs seeded up to the cap may not change";
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp"}, {"learn_until", "0"}})),
                 std::invalid_argument);
}

namespace {

struct GuardedRun {
    RenderCounters counters;
    nlohmann::json rejection, map;
    bool queries_delegated = false;  // the path integrator's queries went to another tester after the first pass
    std::string query_policy;        // ... whose policy is this
};

GuardedRun render_two_rooms_guarded(const std::string &min_occluded, int spp) {
    auto scene = load_scene(two_rooms_path());
    auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp"}, {"max_depth", "4"},
                                                           {"min_occluded", min_occluded}}));
    RenderJob job;
    job.spp = spp;
    RenderResult r = render(*scene, *integ, job);
    const nlohmann::json stats = integ->statistics()["shadow_rays"];
    const ShadowRayTester &tester = dynamic_cast<const PathIntegrator &>(*integ).shadow_rays();
    return {r.counters, stats["rejection"], stats["map"], &tester.query_tester() != &tester,
            tester.query_tester().policy()};
}

}  // namespace

// The first pass traces every shadow ray; rejection then stays on only if enough of them were occluded.
TEST(NeeppRender, RejectionNeedsEnoughOccludedShadowRays) {
    GuardedRun first = render_two_rooms_guarded("0", 1);
    EXPECT_EQ(first.counters.shadow_rays_skipped, 0u) << "the first pass traces every ray";
    const double fraction = first.rejection["first_pass_occluded_fraction"].get<double>();
    ASSERT_GT(fraction, 0.3) << "two rooms behind a door: most shadow rays are blocked";
    ASSERT_LT(fraction, 0.99);
    EXPECT_EQ(first.rejection["first_pass_shadow_rays"].get<uint64_t>(), first.counters.shadow_rays);

    GuardedRun on = render_two_rooms_guarded(std::to_string(fraction - 0.01), 8);
    EXPECT_EQ(on.rejection["state"], "on");
    EXPECT_FALSE(on.queries_delegated);
    EXPECT_GT(on.counters.shadow_rays_skipped, 0u);
    EXPECT_EQ(on.map["source"], "built") << "seeded after the first pass";
    EXPECT_GT(on.map["build_shadow_rays"].get<uint64_t>(), 0u);
    GuardedRun off = render_two_rooms_guarded(std::to_string(fraction + 0.01), 8);
    EXPECT_EQ(off.rejection["state"], "off");
    EXPECT_TRUE(off.queries_delegated) << "with rejection off, queries cost what plain NEE's do";
    EXPECT_EQ(off.query_policy, "nee");
    EXPECT_EQ(off.counters.shadow_rays_skipped, 0u);
    EXPECT_EQ(off.map["source"], "not built") << "no map is seeded for a render that will not use it";
    EXPECT_EQ(off.map["build_shadow_rays"].get<uint64_t>(), 0u);
    EXPECT_DOUBLE_EQ(off.rejection["first_pass_occluded_fraction"].get<double>(), fraction) << "same first pass";
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp"}, {"min_occluded", "1.5"}})),
                 std::invalid_argument);
}

// Distributed rendering merges what renders of different sample ranges learned: the merged map holds the
// base's counts plus every render's additions, exactly, with the first render's other state.
TEST(NeeppRender, MergedStatesAddWhatEachRenderLearned) {
    auto scene = load_scene(two_rooms_path());
    NeeppOptions o;
    o.defer_seeding = false;
    NeeppShadowRays base(o);
    base.prepare(*scene);
    const std::string base_state = base.save_state();
    const VisibilityMap &b = base.map();
    uint64_t seeded = 0, fresh = 0;  // a pair the seeding measured, and one it did not
    while (b.counts_at(seeded).traced == 0) ++seeded;
    while (b.counts_at(fresh).traced != 0) ++fresh;

    auto learned = [&](uint64_t pair_a, uint32_t visible, uint32_t traced) {
        NeeppShadowRays r(o);
        r.prepare(*scene);
        r.restore_state(base_state);
        r.mutable_map().add(pair_a, visible, traced);
        r.mutable_map().add(seeded, 1, 2);
        return r.save_state();
    };
    const std::string first = learned(fresh, 3, 5), second = learned(fresh + 1, 0, 7);
    const std::string merged_state = base.merge_states(base_state, {first, second});
    NeeppShadowRays merged(o);
    merged.prepare(*scene);
    merged.restore_state(merged_state);
    const VisibilityMap &m = merged.map();
    for (uint64_t p = 0; p < m.pair_count(); ++p) {
        PairCounts want = b.counts_at(p);
        if (p == seeded) want = {uint16_t(want.visible + 2), uint16_t(want.traced + 4)};
        if (p == fresh) want = {3, 5};
        if (p == fresh + 1) want = {0, 7};
        ASSERT_EQ(m.counts_at(p).visible, want.visible) << p;
        ASSERT_EQ(m.counts_at(p).traced, want.traced) << p;
    }
    EXPECT_EQ(base.merge_states(base_state, {}), base_state);
    EXPECT_EQ(base.merge_states(base_state, {first}), first);
}

namespace {

// The two rooms standing on a ground plane 400 units across that the camera, inside, never sees.
std::string two_rooms_on_ground_path() {
    std::string xml = two_rooms_xml();
    xml.insert(xml.rfind("</scene>"), R"(  <shape type="rectangle"><transform name="to_world"><scale value="200"/><rotate x="1" angle="-90"/><translate y="-0.01"/></transform><ref id="white"/></shape>
)");
    return write_temp_scene(xml, "rooms_on_ground.xml");
}

}  // namespace

TEST(NeeppRender, ShadingBoundsSpendTheGridWhereTheCameraShades) {
    const std::string path = two_rooms_on_ground_path();
    auto scene = load_scene(path);
    const BBox all = scene->bounds(), shading = shading_bounds(*scene, SeedingOptions{});
    EXPECT_GT(all.extent().x, 300.f);
    // The rooms span x in [-2, 2], y in [0, 2], z in [-1, 1]: the bounds lie within them (the camera's
    // paths need not reach every corner), and cover most of them.
    const Vec3 rooms_lo(-2.01f, -0.02f, -1.01f), rooms_hi(2.01f, 2.01f, 1.01f);
    for (int k = 0; k < 3; ++k) {
        EXPECT_GE(shading.lo[k], rooms_lo[k]) << k;
        EXPECT_LE(shading.hi[k], rooms_hi[k]) << k;
        EXPECT_GT(shading.extent()[k], 0.7f * (rooms_hi[k] - rooms_lo[k])) << k;
    }
    // Renders over that grid agree with plain NEE.
    const OptionMap fitted{{"shadow_rays", "neepp"}, {"grid_bounds", "shading"}};
    std::vector<std::vector<double>> ref, test;
    for (int s = 0; s < 6; ++s) {
        ref.push_back(block_means(render_scene_file(path, 32, 11 + 7919 * s, Options()).image, 6, 6));
        test.push_back(block_means(render_scene_file(path, 32, 23 + 7919 * s, Options(fitted)).image, 6, 6));
    }
    for (const std::string bounds : {"scene", "shading"}) {
        NeeppOptions o;
        o.grid_bounds = bounds;
        NeeppShadowRays tester(o);
        tester.prepare(*scene);
        const int occupied = tester.statistics()["map"]["occupied_voxels"].get<int>();
        if (bounds == "scene") EXPECT_LE(occupied, 32) << "the rooms fit in a column or two of the scene's grid";
        else EXPECT_GT(occupied, 200) << "the rooms cover much of a fitted 16^3 grid";
    }
    expect_same_image(moments_over_seeds(ref), moments_over_seeds(test), "grid_bounds=shading");
}
