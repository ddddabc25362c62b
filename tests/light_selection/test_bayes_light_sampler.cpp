// The Bayesian light sampler (light_selection/bayes_light_sampler.h) after it has learned: the pmf
// sample() reports is still exactly pmf()'s, frequencies follow it (chi-square), every light the BVH can
// reach keeps a probability, it moves probability toward the lights whose samples contributed, and what
// it learned survives a save and restore and merges exactly (distributed rendering).
#include <gtest/gtest.h>
#include "common/chi2.h"
#include "light_test_scenes.h"
#include "neepp/light_selection/bayes_light_sampler.h"
#include "neepp/loader/scene_loader.h"
#include "neepp/math/warp.h"
#include "neepp/sampling/rng.h"
#include "neepp/scene/scene.h"
#include "test_scenes.h"

namespace neepp {
namespace {

using testing::light_rooms_xml;
using testing::write_temp_scene;

const Scene &rooms(bool environment) {
    static std::unique_ptr<Scene> with_env = load_scene(write_temp_scene(light_rooms_xml(5, true), "bayes_env.xml"));
    static std::unique_ptr<Scene> without = load_scene(write_temp_scene(light_rooms_xml(5, false), "bayes_rooms.xml"));
    return environment ? *with_env : *without;
}

std::unique_ptr<BayesLightSampler> make(const Scene &scene, bool second_moment = false) {
    BayesSelectionOptions o;
    o.second_moment = second_moment;
    return std::make_unique<BayesLightSampler>(scene.light_pointers(), VoxelGrid(scene.bounds(), 8), o);
}

std::vector<LightSampleContext> contexts(const Scene &scene, int n, uint64_t seed) {
    PCG32 rng(seed, 1);
    const BBox b = scene.bounds();
    std::vector<LightSampleContext> out;
    for (int i = 0; i < n; ++i) {
        const Vec3 p = b.lo + b.extent() * Vec3(rng.next_float(), rng.next_float(), rng.next_float());
        out.push_back({p, i % 3 == 0 ? Vec3(0.f) : square_to_uniform_sphere(rng.next_2d())});
    }
    return out;
}

// A synthetic world in which light 3 is bright everywhere, the even lights dim and the odd ones (but 3)
// never contribute: what NEE would report there, sample by sample, over a few passes.
void teach(const BayesLightSampler &s, const std::vector<LightSampleContext> &where, int per_context, uint64_t seed) {
    PCG32 rng(seed, 5);
    for (const LightSampleContext &ctx : where)
        for (int k = 0; k < per_context; ++k) {
            const SampledLight l = s.sample(ctx, rng.next_float());
            if (!l.light) continue;
            const uint32_t i = l.light->index;
            const float estimate = i == 3 ? 20.f * (0.5f + rng.next_float()) : i % 2 == 0 ? 0.5f * rng.next_float() : 0.f;
            s.record(ctx, *l.light, estimate);
        }
}

std::unique_ptr<BayesLightSampler> learned(const Scene &scene, bool second_moment, int passes = 3) {
    auto s = make(scene, second_moment);
    for (int p = 0; p < passes; ++p) {
        teach(*s, contexts(scene, 400, 100 + uint64_t(p)), 40, 7 + uint64_t(p));
        s->end_pass();
    }
    return s;
}

class LearnedBayes : public ::testing::TestWithParam<std::tuple<bool, bool>> {};

TEST_P(LearnedBayes, SampleAndPmfAgreeAndEveryReachableLightKeepsAProbability) {
    const auto &[env, va] = GetParam();
    const Scene &scene = rooms(env);
    auto s = learned(scene, va);
    PCG32 rng(3, 3);
    int drawn = 0;
    for (const LightSampleContext &ctx : contexts(scene, 300, 77)) {
        double sum = 0;
        for (const Light *l : scene.light_pointers()) {
            const float p = s->pmf(ctx, *l);
            ASSERT_GE(p, 0.f);
            sum += p;
            if (p > 0) continue;
            for (int k = 0; k < 16; ++k) {  // probability 0 only where the light cannot reach the point
                Color Le;
                const DirectionSample ds = l->sample_direction(ctx.p, rng.next_2d(), Le);
                ASSERT_TRUE(is_black(Le) || !(ds.pdf > 0)) << "a reachable light has probability 0";
            }
        }
        EXPECT_LE(sum, 1.0 + 1e-5);
        for (int k = 0; k < 50; ++k) {
            const SampledLight l = s->sample(ctx, rng.next_float());
            if (!l.light) continue;
            ASSERT_GT(l.pmf, 0.f);
            ASSERT_EQ(l.pmf, s->pmf(ctx, *l.light));
            ++drawn;
        }
    }
    EXPECT_GT(drawn, 10000);
}

TEST_P(LearnedBayes, FrequenciesFollowThePmf) {
    const auto &[env, va] = GetParam();
    const Scene &scene = rooms(env);
    auto s = learned(scene, va);
    const auto lights = scene.light_pointers();
    const uint64_t n = 100000;
    int tested = 0;
    for (const LightSampleContext &ctx : contexts(scene, 12, 9)) {
        std::vector<double> observed(lights.size() + 1, 0.0), expected(lights.size() + 1, 0.0);
        PCG32 rng(23, uint64_t(tested));
        for (uint64_t k = 0; k < n; ++k) {
            const Light *l = s->sample(ctx, rng.next_float()).light;
            observed[l ? l->index : lights.size()] += 1;
        }
        double total = 0;
        for (const Light *l : lights) total += expected[l->index] = double(s->pmf(ctx, *l)) * double(n);
        expected[lights.size()] = std::max(0.0, double(n) - total);  // "no light"
        if (expected[lights.size()] < 1e-3 * double(n)) expected[lights.size()] = 0;
        const test::Chi2Result r = test::chi2_from_histograms(observed, expected);
        ASSERT_TRUE(r.error.empty()) << r.describe();
        EXPECT_GT(r.p_value, 1e-5) << r.describe();
        ++tested;
    }
}

TEST_P(LearnedBayes, MovesProbabilityTowardTheLightsThatContributed) {
    const auto &[env, va] = GetParam();
    const Scene &scene = rooms(env);
    auto fresh = make(scene, va);
    auto s = learned(scene, va);
    const auto lights = scene.light_pointers();
    const Light *bright = nullptr, *dark = nullptr;
    for (const Light *l : lights) {
        if (l->index == 3) bright = l;
        if (l->index == 1) dark = l;
    }
    ASSERT_TRUE(bright && dark);
    double before = 0, after = 0, dark_before = 0, dark_after = 0;
    for (const LightSampleContext &ctx : contexts(scene, 400, 100)) {  // where it was taught
        before += fresh->pmf(ctx, *bright);
        after += s->pmf(ctx, *bright);
        dark_before += fresh->pmf(ctx, *dark);
        dark_after += s->pmf(ctx, *dark);
    }
    EXPECT_GT(after, 1.5 * before);
    EXPECT_LT(dark_after, 0.7 * dark_before);
    EXPECT_GT(s->statistics()["records_learned"].get<uint64_t>(), 10u);
}

INSTANTIATE_TEST_SUITE_P(LightSelection, LearnedBayes, ::testing::Combine(::testing::Bool(), ::testing::Bool()),
                         [](const auto &info) {
                             return std::string(std::get<0>(info.param) ? "env" : "rooms") +
                                    (std::get<1>(info.param) ? "_va" : "_mean");
                         });

// Within a pass nothing changes: reports wait for end_pass, so the pmf a sample was drawn with holds.
TEST(BayesLightSampler, ReportsChangeNothingUntilThePassEnds) {
    const Scene &scene = rooms(false);
    auto s = make(scene);
    const auto where = contexts(scene, 50, 4);
    std::vector<float> before;
    for (const LightSampleContext &ctx : where)
        for (const Light *l : scene.light_pointers()) before.push_back(s->pmf(ctx, *l));
    teach(*s, where, 40, 1);
    size_t i = 0;
    for (const LightSampleContext &ctx : where)
        for (const Light *l : scene.light_pointers()) ASSERT_EQ(s->pmf(ctx, *l), before[i++]);
}

// Save and restore give the same sampler to the bit; merging what renders learned from one base equals
// learning it all in one sampler, to the byte.
TEST(BayesLightSampler, StatesRestoreAndMergeExactly) {
    const Scene &scene = rooms(true);
    auto base = learned(scene, false, 1);
    const std::string base_state = base->save_state();
    auto continued = [&](uint64_t seed) {
        auto s = make(scene);
        s->restore_state(base_state);
        s->end_pass();
        teach(*s, contexts(scene, 200, seed), 30, seed);
        s->end_pass();
        return s;
    };
    auto a = continued(11), b = continued(12);
    // One sampler that hears both renders' reports (drawn from the same frozen tables as each did).
    auto both = make(scene);
    both->restore_state(base_state);
    both->end_pass();
    teach(*both, contexts(scene, 200, 11), 30, 11);
    teach(*both, contexts(scene, 200, 12), 30, 12);
    both->end_pass();
    const std::string merged = BayesLightSampler::merge_encoded(base_state, {a->save_state(), b->save_state()});
    EXPECT_EQ(merged, both->save_state());
    EXPECT_EQ(BayesLightSampler::merge_encoded(base_state, {}), base_state);
    EXPECT_EQ(BayesLightSampler::merge_encoded(base_state, {a->save_state()}), a->save_state());

    auto restored = make(scene);
    restored->restore_state(merged);
    restored->end_pass();
    for (const LightSampleContext &ctx : contexts(scene, 100, 5))
        for (const Light *l : scene.light_pointers()) ASSERT_EQ(restored->pmf(ctx, *l), both->pmf(ctx, *l));
    // A state of another grid is refused with a clear error.
    auto other = std::make_unique<BayesLightSampler>(scene.light_pointers(), VoxelGrid(scene.bounds(), 4));
    EXPECT_THROW(other->restore_state(merged), std::runtime_error);
    EXPECT_THROW(restored->restore_state("not a state"), std::runtime_error);
}

}  // namespace
}  // namespace neepp
