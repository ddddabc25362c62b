// Light selection: the pmf that sample() reports must be exactly what pmf() recomputes (MIS relies on
// it), pmfs must sum to one, selection frequencies must follow them, and zero-power scenes fall back to
// uniform selection.
#include <gtest/gtest.h>

#include "common/chi2.h"
#include "neepp/lights/environment_light.h"
#include "neepp/light_selection/factory.h"

namespace neepp::test {
namespace {

const LightSampleContext kCtx{Vec3(0.3f, -1.f, 2.f), Vec3(0, 0, 1)};

// Point lights of the given intensities, indexed in reverse order so that a sampler confusing its list
// position with Light::index is caught.
struct LightSet {
    std::vector<LightPtr> owned;
    std::vector<const Light *> lights;
    explicit LightSet(const std::vector<Color> &intensities) {
        for (size_t i = 0; i < intensities.size(); ++i) {
            owned.push_back(std::make_unique<PointLight>(Vec3(float(i), 0, 0), intensities[i]));
            owned.back()->index = uint32_t(intensities.size() - 1 - i);
            lights.push_back(owned.back().get());
        }
    }
};

const std::vector<Color> kIntensities = {Color(1.f), Color(5.f, 0.5f, 0.1f), Color(0.2f), Color(0.f),
                                         Color(10.f, 10.f, 30.f), Color(0.05f)};

// Unit samples for exhaustive checks: a dense sweep plus the ends of [0, 1).
std::vector<float> sweep() {
    std::vector<float> us = {0.f, 1e-30f, 0.99999994f};
    for (int k = 0; k < 20000; ++k) us.push_back(float(k) / 20000.f);
    return us;
}

void expect_consistent(const LightSampler &sampler, const std::vector<const Light *> &lights) {
    SCOPED_TRACE(sampler.name());
    for (float u : sweep()) {
        SampledLight s = sampler.sample(kCtx, u);
        ASSERT_NE(s.light, nullptr) << "u=" << u;
        ASSERT_GT(s.pmf, 0.f) << "u=" << u << " chose a light it never should";
        ASSERT_EQ(s.pmf, sampler.pmf(kCtx, *s.light)) << "u=" << u;
    }
    double sum = 0;
    for (const Light *l : lights) sum += sampler.pmf(kCtx, *l);
    EXPECT_NEAR(sum, 1.0, 1e-6);
    if (lights.size() < 2) return;  // one light: the frequencies above say all there is to say

    const uint64_t n = 200000;
    std::vector<double> observed(lights.size(), 0.0), expected(lights.size());
    PCG32 rng(5, 7);
    for (uint64_t s = 0; s < n; ++s) {
        const Light *l = sampler.sample(kCtx, rng.next_float()).light;
        observed[std::find(lights.begin(), lights.end(), l) - lights.begin()] += 1;
    }
    for (size_t i = 0; i < lights.size(); ++i) expected[i] = sampler.pmf(kCtx, *lights[i]) * double(n);
    Chi2Result r = chi2_from_histograms(observed, expected);
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
}

TEST(LightSampler, UniformIsConsistent) {
    LightSet set(kIntensities);
    auto sampler = make_light_sampler("uniform", set.lights);
    expect_consistent(*sampler, set.lights);
    for (const Light *l : set.lights) EXPECT_FLOAT_EQ(sampler->pmf(kCtx, *l), 1.f / float(set.lights.size()));
}

TEST(LightSampler, PowerIsConsistentAndProportionalToPower) {
    LightSet set(kIntensities);
    auto sampler = make_light_sampler("power", set.lights);
    expect_consistent(*sampler, set.lights);
    double total = 0;
    for (const Light *l : set.lights) total += luminance(l->power());
    for (const Light *l : set.lights)
        EXPECT_NEAR(sampler->pmf(kCtx, *l), luminance(l->power()) / total, 1e-6) << "light " << l->index;
}

TEST(LightSampler, ZeroPowerSceneFallsBackToUniform) {
    LightSet set({Color(0.f), Color(0.f), Color(0.f)});
    auto sampler = make_light_sampler("power", set.lights);
    expect_consistent(*sampler, set.lights);
    for (const Light *l : set.lights) EXPECT_FLOAT_EQ(sampler->pmf(kCtx, *l), 1.f / 3.f);
}

// One light takes a shortcut (no search): it must still report the pmf that pmf() reads back, 1, also
// when the light has no power.
TEST(LightSampler, SingleLightIsConsistent) {
    for (const Color &intensity : {Color(3.f), Color(0.f)}) {
        LightSet set({intensity});
        set.owned[0]->index = 4;  // a light of a larger scene, sampled alone
        for (const char *name : {"uniform", "power"}) {
            auto sampler = make_light_sampler(name, set.lights);
            expect_consistent(*sampler, set.lights);
            EXPECT_EQ(sampler->pmf(kCtx, *set.lights[0]), 1.f) << name;
        }
    }
}

TEST(LightSampler, MixedLightKinds) {
    // Infinite lights report power through the scene radius; the tables must still agree.
    std::vector<LightPtr> owned;
    owned.push_back(std::make_unique<ConstantEnvironmentLight>(Color(0.5f)));
    owned.push_back(std::make_unique<PointLight>(Vec3(0.f), Color(20.f)));
    std::vector<const Light *> lights;
    for (size_t i = 0; i < owned.size(); ++i) {
        owned[i]->index = uint32_t(i);
        owned[i]->prepare(BBox{Vec3(-1.f), Vec3(1.f)});
        lights.push_back(owned[i].get());
    }
    for (const char *name : {"uniform", "power"}) expect_consistent(*make_light_sampler(name, lights), lights);
}

TEST(LightSampler, EmptyAndUnknown) {
    for (const char *name : {"uniform", "power"}) {
        auto sampler = make_light_sampler(name, {});
        SampledLight s = sampler->sample(kCtx, 0.5f);
        EXPECT_EQ(s.light, nullptr);
        EXPECT_EQ(s.pmf, 0.f);
    }
    EXPECT_THROW(make_light_sampler("nonsense", {}), std::invalid_argument);
}

}  // namespace
}  // namespace neepp::test
