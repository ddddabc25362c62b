// The path tracer's two forms held together: the fast form (PathBatch: paths in batches, stage by stage,
// packets, lanes) against the reference form (PathIntegrator::Li, one path at a time), which defines the
// estimator. Two checks on every scene family and option the other tests render:
// - sample by sample, where both draw the same random numbers in the same order: the same radiance, up to
//   the rounding in which the lane kernels (hit records, rectangle-light samples) differ from the scalar
//   ones, for all but the few paths that rounding sends another way;
// - image by image, with independent seeds: per-block z-tests (the render loop, its passes and what NEE++
//   learns between them included).
// An error in either form's estimator (a weight, a density, a random number drawn out of turn) shows up
// in most paths it touches, and fails the first check.
#include <gtest/gtest.h>
#include <cmath>
#include "neepp/base/ray_batch.h"
#include "neepp/io/image.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "../light_selection/light_test_scenes.h"
#include "../visibility/visibility_test_scenes.h"
#include "common/seeded_map.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// A room open at the front (paths escape to the environment), with an occluder, textured, glossy and
// specular materials, an area light, a point light and a constant environment.
std::string open_room_xml() {
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
  <emitter type="point"><point name="position" x="-1" y="1.8" z="1"/><rgb name="intensity" value="2"/></emitter>
  <emitter type="constant"><rgb name="radiance" value="0.3"/></emitter>
</scene>)";
}

// A sky with a sun (an environment map) over a floor and a box with a window-like gap, for the
// environment map's sampling and NEE++'s sampling within it (within_light=visibility).
std::string sky_scene_xml() {
    Image sky(64, 32, 3);
    for (int y = 0; y < sky.height; ++y)
        for (int x = 0; x < sky.width; ++x)
            for (int c = 0; c < 3; ++c)
                sky.at(x, y, c) = (0.2f + 0.8f * float(sky.height - y) / float(sky.height)) * (1.f - 0.2f * float(c));
    for (int y = 6; y <= 7; ++y)
        for (int x = 40; x <= 41; ++x)
            for (int c = 0; c < 3; ++c) sky.at(x, y, c) = 200.f;
    const std::string sky_path = write_temp_scene("", "sky.exr");
    write_exr(sky_path, sky);
    return scene_header_xml(5, 70, "0,1,3", "0,0.5,0", 16, 12) + R"(
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></bsdf>
  <emitter type="envmap"><string name="filename" value=")" + sky_path + R"("/></emitter>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform><ref id="white"/></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.8" y="0.05" z="0.8"/><translate y="1.2"/></transform><ref id="white"/></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.05" y="0.6" z="0.8"/><translate x="-0.75" y="0.6"/></transform><ref id="white"/></shape>
  <shape type="sphere"><point name="center" x="0.2" y="0.3" z="0"/><float name="radius" value="0.3"/>
    <bsdf type="roughplastic"><float name="alpha" value="0.2"/></bsdf></shape>
</scene>)";
}

struct Family {
    const char *name;
    std::string (*xml)();
};

const Family kFamilies[] = {
    {"open room", open_room_xml},
    {"glossy room", [] { return std::string(kGlossyRoomXml); }},
    {"light rooms", [] { return light_rooms_xml(4, true); }},
    {"two rooms", [] { return two_rooms_xml(false); }},
    {"window room", [] { return window_room_xml(); }},
    {"sky", sky_scene_xml},
    {"lamps", lamps_xml},
};

// The options the other tests render with: plain NEE and BSDF sampling alone, path lengths, every light
// sampler, every NEE++ shadow-ray policy, sampling within the sky, solid-angle sampling of area lights
// (which the fast form takes through the scalar sampler, not the rectangle lanes), resampled NEE.
const std::vector<OptionMap> kOptionSets = {
    {},
    {{"nee", "false"}},
    {{"max_depth", "2"}, {"hide_emitters", "true"}},
    {{"max_depth", "-1"}, {"rr_depth", "1"}},
    {{"light_sampler", "uniform"}},
    {{"light_sampler", "power"}},
    {{"light_sampler", "spatial-oriented"}},
    {{"light_sampler", "visibility"}},
    {{"light_sampler", "visibility-bvh"}},
    {{"light_sampler", "bayes"}},  // learned in the warm-up's passes: both forms read the same tables
    {{"shadow_rays", "neepp"}},
    {{"shadow_rays", "neepp-adaptive"}},
    {{"shadow_rays", "neepp-cv"}},
    {{"within_light", "visibility"}},
    {{"area_light_sampling", "solid-angle"}},
    {{"area_light_sampling", "solid-angle"}, {"ris", "4"}, {"light_sampler", "power"}},
    {{"ris", "4"}},
    {{"ris", "4"}, {"ris_depth", "-1"}},
    {{"ris", "8"}, {"ris_depth", "3"}, {"shadow_rays", "neepp"}, {"light_sampler", "power"}},
    {{"guiding", "sdtree"}},
    {{"guiding", "sdtree"}, {"ris", "4"}, {"shadow_rays", "neepp"}},
    {{"guiding", "map"}},
    {{"guiding", "map"}, {"ris", "4"}, {"shadow_rays", "neepp"}},
    {{"guiding", "sdtree+map"}, {"guiding_tree_share", "0.3"}},
};

std::string describe(const Family &f, const OptionMap &o) {
    std::string s = f.name;
    for (const auto &[k, v] : o) s += " " + k + "=" + v;
    return s;
}

struct SampleAgreement {
    int samples = 0, exact = 0, close = 0, nonzero = 0;
    RenderCounters fast, reference;
};

// The camera samples of the first kSamples pixel samples, each with its own sampler, evaluated by both
// forms of one integrator after a short render has taken it through its first passes (NEE++'s map seeded,
// its rejection decided, what it learned merged).
SampleAgreement compare_samples(const std::string &scene_path, const OptionMap &o) {
    auto scene = load_scene(scene_path);
    // Every integrator with a map starts from the one the scene's first seeded (common/seeded_map.h).
    const OptionMap options = with_map_file(o, map_file_beside(scene_path));
    auto integrator = make_integrator("path", with_scene_options(*scene, Options(options)));
    RenderJob warm_up;
    warm_up.spp = 3;
    warm_up.seed = 11;
    render(*scene, *integrator, warm_up);

    const Camera &cam = scene->camera;
    constexpr int kSamples = 600;
    auto start = [&](Sampler &s, int i) {
        const int x = i % cam.width, y = (i / cam.width) % cam.height;
        s.start_sample(uint32_t(x), uint32_t(y), uint32_t(i));
        return cam.pixel_ray(x, y, s.next_2d(), Vec2(0.5f, 0.5f));
    };
    std::vector<std::unique_ptr<Sampler>> owned;
    std::vector<Sampler *> samplers;
    std::vector<Ray> rays;
    for (int i = 0; i < kSamples; ++i) {
        samplers.push_back(owned.emplace_back(make_sampler("independent", 7)).get());
        rays.push_back(start(*samplers.back(), i));
    }
    SampleAgreement a;
    std::vector<Color> fast(kSamples);
    const auto &path = dynamic_cast<const RayIntegrator &>(*integrator);
    const RayBatch *batch = path.batch();
    EXPECT_NE(batch, nullptr) << "the fast form renders by default";
    if (!batch) return a;
    batch->Li_batch(*scene, rays, samplers, fast, a.fast);
    auto single = make_sampler("independent", 7);
    for (int i = 0; i < kSamples; ++i) {
        const Ray ray = start(*single, i);
        const Color L = path.Li(*scene, ray, *single, a.reference);
        bool exact = true, close = true;
        for (int c = 0; c < 3; ++c) {
            exact &= L[c] == fast[i][c];
            close &= std::abs(L[c] - fast[i][c]) <= 1e-3f * std::max(std::abs(L[c]), std::abs(fast[i][c])) + 1e-6f;
        }
        ++a.samples;
        a.exact += exact;
        a.close += close;
        a.nonzero += !is_black(L);
    }
    return a;
}

TEST(PathForms, SameRadianceSampleBySample) {
    int samples = 0, disagree = 0;
    for (const Family &family : kFamilies) {
        const std::string scene_path = write_temp_scene(family.xml());
        for (const OptionMap &o : kOptionSets) {
            const std::string what = describe(family, o);
            SCOPED_TRACE(what);
            const SampleAgreement a = compare_samples(scene_path, o);
            std::printf("%-70s %3d of %d close, %3d to the bit, %3d lit; rays %llu / %llu, shadow rays %llu / %llu\n",
                        what.c_str(), a.close, a.samples, a.exact, a.nonzero, (unsigned long long)a.fast.rays,
                        (unsigned long long)a.reference.rays, (unsigned long long)a.fast.shadow_rays,
                        (unsigned long long)a.reference.shadow_rays);
            EXPECT_GE(a.nonzero, 10) << "the comparison is about real paths, not black ones";
            // Rounding may send a path another way now and then (a grazing hit, a roulette at its edge):
            // none did on the machines this was written on, over all the cases here.
            EXPECT_GE(a.close, a.samples - a.samples / 100) << a.close << " of " << a.samples << " agree";
            samples += a.samples;
            disagree += a.samples - a.close;
            // The same rays, but for such paths.
            EXPECT_NEAR(double(a.fast.rays), double(a.reference.rays), 0.01 * double(a.reference.rays));
            EXPECT_NEAR(double(a.fast.shadow_rays), double(a.reference.shadow_rays), 0.01 * double(a.reference.shadow_rays) + 2);
        }
    }
    // An error on a rare kind of path (a weight wrong only for some emitters hit) may stay under the
    // per-case bound; summed over every case it does not.
    EXPECT_LE(disagree, samples / 1000) << disagree << " of " << samples << " samples disagree";
}

// The first check fails where the forms differ: a fast form that drew one number out of turn, or dropped
// a MIS weight, would not pass it. Here the two "forms" are two estimators that differ on purpose (BSDF
// sampling alone and NEE, of the same image): sample by sample they must disagree.
TEST(PathForms, SampleCheckSeesADifferentEstimator) {
    auto scene = load_scene(write_temp_scene(kGlossyRoomXml));
    auto nee_owned = make_integrator("path", with_scene_options(*scene, Options()));
    auto bsdf_only_owned = make_integrator("path", with_scene_options(*scene, Options(OptionMap{{"nee", "false"}})));
    auto *nee = dynamic_cast<RayIntegrator *>(nee_owned.get());
    auto *bsdf_only = dynamic_cast<RayIntegrator *>(bsdf_only_owned.get());
    nee->prepare(*scene);
    bsdf_only->prepare(*scene);
    const Camera &cam = scene->camera;
    int close = 0, n = 0;
    RenderCounters counters;
    for (int i = 0; i < 300; ++i, ++n) {
        auto a = make_sampler("independent", 7), b = make_sampler("independent", 7);
        a->start_sample(uint32_t(i % cam.width), uint32_t(i / cam.width % cam.height), uint32_t(i));
        b->start_sample(uint32_t(i % cam.width), uint32_t(i / cam.width % cam.height), uint32_t(i));
        const Ray ray = cam.pixel_ray(i % cam.width, i / cam.width % cam.height, a->next_2d(), Vec2(0.5f, 0.5f));
        b->next_2d();
        const Color La = nee->Li(*scene, ray, *a, counters), Lb = bsdf_only->Li(*scene, ray, *b, counters);
        close += std::abs(La[1] - Lb[1]) <= 1e-3f * std::max(std::abs(La[1]), std::abs(Lb[1])) + 1e-6f;
    }
    EXPECT_LT(close, n * 97 / 100);
}

// Whole renders, with independent seeds: the render loop's passes and what NEE++ learns between them.
TEST(PathForms, SameImageInExpectation) {
    const std::vector<std::pair<int, OptionMap>> cases = {  // (family, options)
        {0, {}}, {0, {{"nee", "false"}}}, {0, {{"ris", "4"}, {"ris_depth", "-1"}}},
        {1, {}}, {1, {{"shadow_rays", "neepp-adaptive"}}}, {1, {{"shadow_rays", "neepp-cv"}}},
        {2, {{"light_sampler", "visibility"}}}, {2, {{"shadow_rays", "neepp"}, {"ris", "4"}}},
        {3, {{"shadow_rays", "neepp"}}}, {4, {{"shadow_rays", "neepp-adaptive"}}},
        {5, {{"within_light", "visibility"}}}, {5, {{"max_depth", "-1"}, {"rr_depth", "1"}}},
        {6, {{"area_light_sampling", "solid-angle"}}}, {0, {{"area_light_sampling", "solid-angle"}}},
        {0, {{"guiding", "sdtree"}}}, {5, {{"guiding", "sdtree"}, {"guiding_bsdf_fraction", "0.3"}, {"guiding_learn_direct", "false"}}},
        {0, {{"guiding", "map"}}}, {5, {{"guiding", "map"}, {"guiding_bsdf_fraction", "0.3"}, {"guiding_learn_direct", "false"}}},
        {5, {{"guiding", "sdtree+map"}}},
    };
    for (auto [family, o] : cases) {
        const std::string what = describe(kFamilies[family], o);
        const std::string path = write_temp_scene(kFamilies[family].xml());
        o = with_map_file(o, map_file_beside(path));  // the eight renders of a case (both forms) seed one map
        const BlockMoments fast = block_moments(path, "path", Options(o), 4, 16, 101);
        o["form"] = "reference";
        const BlockMoments reference = block_moments(path, "path", Options(o), 4, 16, 202);
        expect_same_image(reference, fast, what);
    }
}

TEST(PathForms, FormIsAnOption) {
    auto reference = make_integrator("path", Options(OptionMap{{"form", "reference"}}));
    EXPECT_EQ(reference->describe()["form"], "reference");
    EXPECT_EQ(dynamic_cast<RayIntegrator &>(*reference).batch(), nullptr) << "the render loop then calls Li";
    EXPECT_EQ(make_integrator("path", Options())->describe()["form"], "fast");
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"form", "wavefront"}})), std::invalid_argument);
}

}  // namespace
