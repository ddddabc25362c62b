// The path integrator's batched evaluation (Li_batch: paths in lockstep, stage by stage, with
// prefetches) must be the same computation as Li, path by path: same random numbers in the same order,
// same result to the bit, whatever the batch's size and however its paths end (escape, absorption,
// Russian roulette, maximum depth), with plain NEE, with NEE++'s shadow-ray rejection and with resampled NEE.
#include <gtest/gtest.h>
#include "neepp/sampling/sampler.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// A room open at the front (paths escape to the environment), with an occluder, textured, glossy and
// specular materials, an area light and a constant environment.
std::string room_xml() {
    return scene_header_xml(12, 60, "0,1,3.5", "0,0.8,0", 16, 12) + R"(
  <bsdf type="twosided" id="checker"><bsdf type="diffuse">
    <texture name="reflectance" type="checkerboard"><rgb name="color0" value="0.8,0.2,0.2"/><rgb name="color1" value="0.2,0.2,0.8"/></texture>
  </bsdf></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/></transform><ref id="checker"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><translate z="-2"/></transform>
    <bsdf type="roughplastic"><float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.5,0.6,0.4"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.6" y="0.5" z="0.3"/><float name="radius" value="0.4"/>
    <bsdf type="dielectric"/></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.4"/><translate x="-0.5" y="0.4" z="-0.3"/></transform>
    <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.2"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="2.5"/></transform>
    <emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.3"/></emitter>
</scene>)";
}

void expect_batch_equals_single(const Options &options) {
    auto scene = load_scene(write_temp_scene(room_xml()));
    auto integrator = make_integrator("path", options);
    integrator->prepare(*scene);
    const Camera &cam = scene->camera;
    // 150 samples: several full batches and a partial one, whatever the integrator's batch size.
    constexpr int kSamples = 150;
    std::vector<std::unique_ptr<Sampler>> owned;
    std::vector<Sampler *> samplers;
    std::vector<Ray> rays;
    auto start = [&](Sampler &s, int i) {
        s.start_sample(uint32_t(i % cam.width), uint32_t((i / cam.width) % cam.height), uint32_t(i));
        Vec2 j = s.next_2d();
        return cam.generate_ray({(float(i % cam.width) + j.x) / float(cam.width),
                                 (float((i / cam.width) % cam.height) + j.y) / float(cam.height)});
    };
    for (int i = 0; i < kSamples; ++i) {
        samplers.push_back(owned.emplace_back(make_sampler("independent", 7)).get());
        rays.push_back(start(*samplers.back(), i));
    }
    std::vector<Color> batched(kSamples);
    RenderCounters batch_counters, single_counters;
    integrator->Li_batch(*scene, rays, samplers, batched, batch_counters);

    auto single = make_sampler("independent", 7);
    int nonzero = 0;
    for (int i = 0; i < kSamples; ++i) {
        Ray ray = start(*single, i);
        Color L = integrator->Li(*scene, ray, *single, single_counters);
        for (int c = 0; c < 3; ++c) ASSERT_EQ(L[c], batched[i][c]) << "sample " << i << " channel " << c;
        nonzero += !is_black(L);
    }
    EXPECT_GT(nonzero, kSamples / 2);  // the comparison is about real paths, not black ones
    EXPECT_EQ(batch_counters.rays, single_counters.rays);
    EXPECT_EQ(batch_counters.shadow_rays, single_counters.shadow_rays);
}

TEST(PathIntegratorBatch, SameAsOnePathAtATimeWithNee) { expect_batch_equals_single(Options()); }

TEST(PathIntegratorBatch, SameAsOnePathAtATimeWithNeepp) {
    expect_batch_equals_single(Options(OptionMap{{"shadow_rays", "neepp"}}));
}

TEST(PathIntegratorBatch, SameAsOnePathAtATimeWithResampling) {
    expect_batch_equals_single(Options(OptionMap{{"ris", "4"}}));  // at the first vertex only
    expect_batch_equals_single(Options(OptionMap{{"ris", "4"}, {"ris_depth", "-1"}}));
    expect_batch_equals_single(Options(OptionMap{{"ris", "8"}, {"ris_depth", "3"}, {"shadow_rays", "neepp"}, {"light_sampler", "power"}}));
}

}  // namespace
