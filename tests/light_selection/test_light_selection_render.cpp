// Every light sampler renders the same image as power sampling on a many-light scene (z-tests on the
// image mean and coarse blocks over independent seeds, as the NEE++ policy tests do), alone and combined
// with NEE++'s shadow-ray rejection, with and without an environment light; and the visibility-aware
// sampler spends its shadow rays on visible lights (fewer occluded rays than power sampling).
#include <gtest/gtest.h>
#include <map>
#include "light_test_scenes.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

constexpr int kSeeds = 6;
constexpr int kSpp = 32;

struct SamplerRun : BlockMoments {
    uint64_t shadow_rays = 0, occluded = 0;
};

SamplerRun render_moments(const std::string &path, const std::string &sampler, const std::string &policy, uint64_t seed0) {
    std::vector<std::vector<double>> per_seed;
    SamplerRun run;
    for (int s = 0; s < kSeeds; ++s) {
        RenderedImage r = render_scene_file(path, kSpp, seed0 + uint64_t(s) * 7919,
                                            Options(OptionMap{{"light_sampler", sampler}, {"shadow_rays", policy}}));
        run.shadow_rays += r.result.counters.shadow_rays;
        run.occluded += r.result.counters.shadow_rays_occluded;
        per_seed.push_back(block_means(r.image, 6, 6));
    }
    static_cast<BlockMoments &>(run) = moments_over_seeds(per_seed);
    return run;
}

const std::string &scene_path(bool environment) {
    static std::string rooms = write_temp_scene(light_rooms_xml(5, false), "rooms.xml");
    static std::string env = write_temp_scene(light_rooms_xml(5, true), "rooms_env.xml");
    return environment ? env : rooms;
}

const SamplerRun &power_reference(bool environment) {
    static std::map<bool, SamplerRun> cache;
    auto it = cache.find(environment);
    if (it == cache.end()) it = cache.emplace(environment, render_moments(scene_path(environment), "power", "nee", 101)).first;
    return it->second;
}

class SamplerRender : public ::testing::TestWithParam<std::tuple<std::string, std::string, bool>> {};

TEST_P(SamplerRender, AgreesWithPowerSampling) {
    const auto &[sampler, policy, env] = GetParam();
    const SamplerRun &ref = power_reference(env);
    SamplerRun run = render_moments(scene_path(env), sampler, policy, 5003);
    expect_same_image(ref, run, sampler + " + " + policy + (env ? " with environment" : ""));
}

INSTANTIATE_TEST_SUITE_P(LightSelection, SamplerRender,
                         ::testing::Combine(::testing::Values("uniform", "spatial", "spatial-oriented", "bvh", "visibility", "visibility-power",
                                                              "visibility-bvh", "bayes", "bayes-va"),
                                            ::testing::Values("nee", "neepp"), ::testing::Bool()),
                         [](const auto &info) {
                             std::string n = std::get<0>(info.param) + "_" + std::get<1>(info.param) +
                                             (std::get<2>(info.param) ? "_env" : "");
                             for (char &c : n) if (c == '-') c = '_';
                             return n;
                         });

TEST(LightSelectionRender, VisibilitySamplerWastesFewerShadowRays) {
    const SamplerRun &power = power_reference(false);
    SamplerRun vis = render_moments(scene_path(false), "visibility", "nee", 101);
    const double power_occluded = double(power.occluded) / double(power.shadow_rays);
    const double vis_occluded = double(vis.occluded) / double(vis.shadow_rays);
    EXPECT_LT(vis_occluded, 0.7 * power_occluded) << "occluded fraction: power " << power_occluded << " visibility " << vis_occluded;
}

// The Bayesian sampler learns from the render's own NEE samples, in the fast form and the reference form
// alike: over the passes of one render it hears of samples and builds records, and its renders agree with
// power sampling after that learning too (a second set of seeds at more samples, so most of the image
// comes from passes that read learned tables).
TEST(LightSelectionRender, BayesSamplerLearnsOverPassesInBothForms) {
    for (const char *form : {"fast", "reference"}) {
        auto scene = load_scene(scene_path(false));
        auto integ = make_integrator("path", with_scene_options(*scene, Options(OptionMap{{"light_sampler", "bayes"}, {"form", form}})));
        RenderJob job;
        job.spp = 24;
        job.seed = 3;
        RenderResult r = render(*scene, *integ, job);
        const nlohmann::json s = integ->statistics()["light_sampler"];
        EXPECT_EQ(s["used"], "bayes");
        EXPECT_GE(r.passes, 3) << form;
        EXPECT_GE(s["passes"].get<uint64_t>(), 2u) << form;
        EXPECT_GT(s["samples_learned"].get<uint64_t>(), 1000u) << form;
        EXPECT_GT(s["records_learned"].get<uint64_t>(), 10u) << form;
    }
    SamplerRun learned;
    std::vector<std::vector<double>> per_seed;
    for (int k = 0; k < kSeeds; ++k) {
        RenderedImage r = render_scene_file(scene_path(false), 4 * kSpp, 9001 + uint64_t(k) * 7919,
                                            Options(OptionMap{{"light_sampler", "bayes"}}));
        per_seed.push_back(block_means(r.image, 6, 6));
    }
    static_cast<BlockMoments &>(learned) = moments_over_seeds(per_seed);
    expect_same_image(power_reference(false), learned, "bayes after learning, at 128 spp, against power");
    // ... and against plain NEE with the light BVH, the sampler whose cut and descent it reweights.
    std::vector<std::vector<double>> bvh_seeds;
    for (int k = 0; k < kSeeds; ++k) {
        RenderedImage r = render_scene_file(scene_path(false), 4 * kSpp, 31 + uint64_t(k) * 7919,
                                            Options(OptionMap{{"light_sampler", "bvh"}}));
        bvh_seeds.push_back(block_means(r.image, 6, 6));
    }
    BlockMoments bvh = moments_over_seeds(bvh_seeds);
    expect_same_image(bvh, learned, "bayes after learning, at 128 spp, against bvh");
}

// Distributed rendering: the path integrator merges what renders with the Bayesian sampler learned,
// through an integrator that was never prepared (as neepp.distributed merges), into a state that holds
// every render's samples.
TEST(LightSelectionRender, BayesStatesMergeThroughTheIntegrator) {
    auto scene = load_scene(scene_path(false));
    const Options options = with_scene_options(*scene, Options(OptionMap{{"light_sampler", "bayes"}}));
    auto fresh = make_integrator("path", options);
    fresh->prepare(*scene);
    const std::string base = fresh->save_state();
    auto learned = [&](uint64_t seed, uint64_t &samples) {
        auto integ = make_integrator("path", options);
        RenderJob job;
        job.spp = 6;
        job.seed = seed;
        render(*scene, *integ, job);
        samples = integ->statistics()["light_sampler"]["samples_learned"].get<uint64_t>();
        return integ->save_state();
    };
    uint64_t na = 0, nb = 0;
    const std::string a = learned(1, na), b = learned(2, nb);
    ASSERT_GT(na, 0u);
    ASSERT_GT(nb, 0u);
    auto merger = make_integrator("path", options);  // never prepared
    const std::string merged = merger->merge_states(base, {a, b});
    auto resumed = make_integrator("path", options);
    resumed->prepare(*scene);
    resumed->restore_state(*scene, merged);
    EXPECT_EQ(resumed->statistics()["light_sampler"]["samples_learned"].get<uint64_t>(), na + nb);
    EXPECT_EQ(merger->merge_states(base, {a}), a);
}

}  // namespace
