// Every light sampler on a many-light scene: the pmf sample() reports is exactly what pmf() recomputes
// (MIS relies on it), selection frequencies follow the pmf (chi-square, with "no light" as an outcome for
// samplers that may return none), sample_many is sample for each number (to the bit), every light that
// can contribute keeps a nonzero probability, lazily built tables do not depend on which thread built
// them, and the visibility-aware sampler moves probability toward the lights the map says are visible
// and follows the map as it learns.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include "common/chi2.h"
#include "light_test_scenes.h"
#include "neepp/light_selection/factory.h"
#include "neepp/light_selection/visibility_light_sampler.h"
#include "neepp/loader/scene_loader.h"
#include "neepp/math/warp.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/neepp_shadow_rays.h"
#include "test_scenes.h"

namespace neepp {
namespace {

using testing::light_rooms_xml;
using testing::write_temp_scene;

// The scene, NEE++'s map over it, and a sampler of each kind.
struct Fixture {
    std::unique_ptr<Scene> scene;
    std::unique_ptr<NeeppShadowRays> map_owner;
    explicit Fixture(bool environment) {
        scene = load_scene(write_temp_scene(light_rooms_xml(5, environment), environment ? "env.xml" : "rooms.xml"));
        NeeppOptions o;
        o.policy = ShadowRayPolicy::TraceAll;
        map_owner = std::make_unique<NeeppShadowRays>(o);
        map_owner->prepare(*scene);
    }
    std::unique_ptr<LightSampler> make(const std::string &name) const {
        LightSelectionInputs in{scene.get(), map_owner->voxel_grid(), map_owner->visibility_map(), 16};
        return make_light_sampler(name, scene->light_pointers(), in);
    }
    // Shading contexts spread over the scene's interior, with and without a normal.
    std::vector<LightSampleContext> contexts(int n, uint64_t seed) const {
        PCG32 rng(seed, 1);
        BBox b = scene->bounds();
        std::vector<LightSampleContext> out;
        for (int i = 0; i < n; ++i) {
            Vec3 u(rng.next_float(), rng.next_float(), rng.next_float());
            Vec3 p = b.lo + b.extent() * u;
            Vec3 nrm = i % 3 == 0 ? Vec3(0.f) : square_to_uniform_sphere(rng.next_2d());
            out.push_back({p, nrm});
        }
        return out;
    }
};

const Fixture &fixture(bool environment) {
    static Fixture with_env(true), without_env(false);
    return environment ? with_env : without_env;
}

class EverySampler : public ::testing::TestWithParam<std::tuple<std::string, bool>> {};

TEST_P(EverySampler, SampleAndPmfAgreeExactly) {
    const auto &[name, env] = GetParam();
    const Fixture &f = fixture(env);
    auto sampler = f.make(name);
    auto lights = f.scene->light_pointers();
    PCG32 rng(17, 3);
    int drawn = 0;
    for (const LightSampleContext &ctx : f.contexts(300, 5)) {
        double sum = 0;
        for (const Light *l : lights) {
            float p = sampler->pmf(ctx, *l);
            ASSERT_GE(p, 0.f);
            sum += p;
        }
        // Only the BVHs may give no light at all (where no light's bounds can reach the point).
        const bool bvh = name.find("bvh") != std::string::npos || name.rfind("bayes", 0) == 0;
        if (bvh) EXPECT_LE(sum, 1.0 + 1e-5);
        else EXPECT_NEAR(sum, 1.0, 1e-5);
        for (int k = 0; k < 50; ++k) {
            SampledLight s = sampler->sample(ctx, rng.next_float());
            if (!s.light) {
                ASSERT_TRUE(bvh) << "only the BVHs may return no light";
                continue;
            }
            ASSERT_GT(s.pmf, 0.f);
            ASSERT_EQ(s.pmf, sampler->pmf(ctx, *s.light));
            ++drawn;
        }
    }
    EXPECT_GT(drawn, 10000);
}

TEST_P(EverySampler, SampleManyIsSampleForEachNumber) {
    const auto &[name, env] = GetParam();
    const Fixture &f = fixture(env);
    auto sampler = f.make(name);
    PCG32 rng(31, 7);
    for (const LightSampleContext &ctx : f.contexts(200, 19))
        for (int n : {1, 8, 70}) {  // 70: more than the BVH descends at once
            std::vector<float> u(static_cast<size_t>(n));
            for (float &x : u) x = rng.next_float();
            std::vector<SampledLight> many(static_cast<size_t>(n));
            sampler->sample_many(ctx, u.data(), n, many.data());
            for (int i = 0; i < n; ++i) {
                const SampledLight one = sampler->sample(ctx, u[size_t(i)]);
                ASSERT_EQ(many[size_t(i)].light, one.light) << name << " sample " << i << " of " << n;
                ASSERT_EQ(many[size_t(i)].pmf, one.pmf) << name << " sample " << i << " of " << n;
            }
        }
}

TEST_P(EverySampler, FrequenciesFollowThePmf) {
    const auto &[name, env] = GetParam();
    const Fixture &f = fixture(env);
    auto sampler = f.make(name);
    auto lights = f.scene->light_pointers();
    const uint64_t n = 100000;
    int tested = 0;
    for (const LightSampleContext &ctx : f.contexts(12, 9)) {
        std::vector<double> observed(lights.size() + 1, 0.0), expected(lights.size() + 1, 0.0);
        PCG32 rng(23, uint64_t(tested));
        for (uint64_t s = 0; s < n; ++s) {
            const Light *l = sampler->sample(ctx, rng.next_float()).light;
            observed[l ? l->index : lights.size()] += 1;
        }
        double total = 0;
        for (const Light *l : lights) total += expected[l->index] = double(sampler->pmf(ctx, *l)) * double(n);
        expected[lights.size()] = std::max(0.0, double(n) - total);  // "no light"
        if (expected[lights.size()] < 1e-3 * double(n)) expected[lights.size()] = 0;
        test::Chi2Result r = test::chi2_from_histograms(observed, expected);
        ASSERT_TRUE(r.error.empty()) << name << ": " << r.describe();
        EXPECT_GT(r.p_value, 1e-5) << name << ": " << r.describe();
        ++tested;
    }
}

TEST_P(EverySampler, EveryLightThatCanContributeKeepsAProbability) {
    const auto &[name, env] = GetParam();
    const Fixture &f = fixture(env);
    auto sampler = f.make(name);
    PCG32 rng(29, 1);
    for (const LightSampleContext &ctx : f.contexts(200, 13)) {
        for (const Light *l : f.scene->light_pointers()) {
            if (sampler->pmf(ctx, *l) > 0) continue;
            // Zero probability is only allowed where the light cannot send anything to the point.
            for (int s = 0; s < 32; ++s) {
                Color Le;
                DirectionSample ds = l->sample_direction(ctx.p, rng.next_2d(), Le);
                ASSERT_TRUE(is_black(Le) || !(ds.pdf > 0)) << name << " gives a reachable light probability 0";
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(LightSelection, EverySampler,
                         ::testing::Combine(::testing::Values("uniform", "power", "spatial", "spatial-oriented", "bvh", "visibility",
                                                              "visibility-power", "visibility-bvh", "bayes", "bayes-va"),
                                            ::testing::Bool()),
                         [](const auto &info) {
                             std::string n = std::get<0>(info.param) + (std::get<1>(info.param) ? "_env" : "");
                             for (char &c : n) if (c == '-') c = '_';
                             return n;
                         });

TEST(LightSelection, LazyTablesDoNotDependOnTheBuildingThread) {
    const Fixture &f = fixture(true);
    auto contexts = f.contexts(2000, 31);
    auto lights = f.scene->light_pointers();
    for (const char *name : {"spatial", "spatial-oriented", "visibility", "visibility-bvh"}) {
        auto serial = f.make(name), parallel = f.make(name);
        std::vector<float> a(contexts.size() * lights.size()), b(a.size());
        for (size_t i = 0; i < contexts.size(); ++i)
            for (size_t l = 0; l < lights.size(); ++l) a[i * lights.size() + l] = serial->pmf(contexts[i], *lights[l]);
        tbb::parallel_for(size_t(0), contexts.size(), [&](size_t i) {
            for (size_t l = 0; l < lights.size(); ++l) b[i * lights.size() + l] = parallel->pmf(contexts[i], *lights[l]);
        });
        EXPECT_EQ(a, b) << name;
    }
}

TEST(LightSelection, VisibilitySamplerFavoursTheLightsTheMapSeesAndFollowsTheMap) {
    const Fixture &f = fixture(false);
    auto lights = f.scene->light_pointers();
    // A point on the floor of the first room (a surface the map was seeded from): its own light
    // (index 0) is the only one in view.
    LightSampleContext ctx{Vec3(1.f, 0.001f, 0.2f), Vec3(0, 1, 0)};
    auto power = f.make("power"), spatial = f.make("spatial"), vis = f.make("visibility-power");
    const float p_power = power->pmf(ctx, *lights[0]), p_vis = vis->pmf(ctx, *lights[0]);
    EXPECT_GT(p_vis, 0.25f);
    EXPECT_GT(p_vis, 3 * p_power) << "visibility weighting should move probability to the visible light";
    EXPECT_GT(f.make("visibility")->pmf(ctx, *lights[0]), spatial->pmf(ctx, *lights[0]));

    // A map that claims the first room's light is never visible from anywhere: after end_pass the
    // sampler reads it; the light keeps at least the defensive share.
    VisibilityMap map = *f.map_owner->visibility_map();
    const VoxelGrid &grid = *f.map_owner->voxel_grid();
    VisibilitySelectionOptions options;
    options.base = "power";
    VisibilityLightSampler sampler(lights, grid, map, f.scene->bounds().center(), options);
    const float before = sampler.pmf(ctx, *lights[0]);
    EXPECT_NEAR(before, p_vis, 1e-6f);
    const uint32_t a = grid.voxel_of(ctx.p);
    const auto coverage = light_coverage(grid, {lights[0]}, ctx.p);
    for (const CellWeight &cw : coverage[0]) map.set(a, cw.cell, PairCounts{0, 1000});
    EXPECT_EQ(sampler.pmf(ctx, *lights[0]), before) << "tables must stay frozen within a pass";
    sampler.end_pass();
    const float after = sampler.pmf(ctx, *lights[0]);
    EXPECT_LT(after, 0.5f * before);
    EXPECT_GE(after, 0.1f * p_power * 0.99f) << "the defensive share";
}

// With more lights than SpatialEstimateOptions::light_samples_per_table / points_per_voxel (256), the
// spatial estimate takes fewer points per table (one at 4096 lights and beyond): the tables stay exact
// distributions, sample() and pmf() agree, and every light keeps its defensive share.
TEST(LightSelection, TablesOverHundredsOfLightsStayExact) {
    std::string xml = testing::scene_header_xml(3, 70, "0.2,1,0.2", "2,0.8,2", 16, 12) + R"(
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.6"/></bsdf>
  <shape type="cube"><transform name="to_world"><scale x="2" y="1" z="2"/><translate x="2" y="1" z="2"/></transform><ref id="white"/></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.05" y="1" z="1"/><translate x="2" y="1" z="1"/></transform><ref id="white"/></shape>
)";
    const int side = 24;  // 576 lights: 7 points per table instead of 16
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j)
            xml += "  <shape type=\"rectangle\"><transform name=\"to_world\"><scale x=\"0.04\" y=\"0.04\"/><rotate x=\"1\" angle=\"90\"/>"
                   "<translate x=\"" + std::to_string(4.f * (i + 0.5f) / side) + "\" y=\"1.98\" z=\"" + std::to_string(4.f * (j + 0.5f) / side) +
                   "\"/></transform><emitter type=\"area\"><rgb name=\"radiance\" value=\"" + std::to_string(1 + (i * 7 + j * 3) % 11) +
                   "\"/></emitter></shape>\n";
    xml += "</scene>\n";
    auto scene = load_scene(testing::write_temp_scene(xml, "many_lights.xml"));
    NeeppOptions o;
    o.policy = ShadowRayPolicy::TraceAll;
    NeeppShadowRays neepp(o);
    neepp.prepare(*scene);
    auto lights = scene->light_pointers();
    ASSERT_EQ(lights.size(), size_t(side * side));
    LightSelectionInputs in{scene.get(), neepp.voxel_grid(), neepp.visibility_map(), 16};
    PCG32 rng(41, 5);
    for (const char *name : {"spatial", "spatial-oriented", "visibility"}) {
        auto sampler = make_light_sampler(name, lights, in);
        for (int c = 0; c < 12; ++c) {
            const LightSampleContext ctx{Vec3(0.2f + 3.6f * rng.next_float(), 0.1f + 1.7f * rng.next_float(), 0.2f + 3.6f * rng.next_float()),
                                         Vec3(0.f, 1.f, 0.f)};
            double sum = 0;
            float smallest = 1;
            for (const Light *l : lights) {
                const float p = sampler->pmf(ctx, *l);
                sum += p;
                smallest = std::min(smallest, p);
            }
            EXPECT_NEAR(sum, 1.0, 1e-4) << name;
            EXPECT_GT(smallest, 0.f) << name << ": a light lost its defensive share";
            for (int k = 0; k < 20; ++k) {
                const SampledLight s = sampler->sample(ctx, rng.next_float());
                ASSERT_TRUE(s.light) << name;
                ASSERT_EQ(s.pmf, sampler->pmf(ctx, *s.light)) << name;
            }
        }
    }
}

}  // namespace
}  // namespace neepp
