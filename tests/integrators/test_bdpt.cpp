// Bidirectional path tracing and light tracing estimate what the path tracer does: on glossy, textured
// and diffuse materials, per strategy (MIS-weighted strategies add up to the image; unweighted ones
// each estimate it where they can sample every path), with shading normals (Veach's correction), with
// NEE++ light-subpath selection over a map that is badly wrong, and to the bit for a seed.
#include <gtest/gtest.h>
#include <fmt/core.h>
#include <cstring>
#include <filesystem>
#include <fstream>
#include "neepp/integrators/bdpt.h"
#include "neepp/visibility/neepp_shadow_rays.h"
#include "common/seeded_map.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

TEST(BDPT, AgreesWithPathTracingOnAGlossyRoom) {
    const std::string path = write_temp_scene(kGlossyRoomXml);
    const BlockMoments ref = block_moments(path, "path", Options(), 6, 48, 100);
    expect_same_image(ref, block_moments(path, "bdpt", Options(), 6, 16, 200), "bdpt (power heuristic)");
    expect_same_image(ref, block_moments(path, "bdpt", Options(OptionMap{{"mis", "balance"}}), 6, 16, 300),
                      "bdpt (balance heuristic)");
}

TEST(LightTracer, AgreesWithPathTracingOnAGlossyRoom) {
    const std::string path = write_temp_scene(kGlossyRoomXml);
    const BlockMoments ref = block_moments(path, "path", Options(), 6, 48, 100);
    expect_same_image(ref, block_moments(path, "light", Options(), 6, 48, 400), "light tracing");
}

TEST(BDPT, MisWeightedStrategiesAddUpToTheImage) {
    const std::string path = write_temp_scene(kGlossyRoomXml);
    Options full(OptionMap{{"max_depth", "3"}});
    const BlockMoments whole = block_moments(path, "bdpt", full, 6, 16, 500);
    // Every strategy of paths of at most 3 edges (s + t <= 4) but (1, 1), which BDPT leaves to (0, 2).
    BlockMoments sum;
    int k = 0;
    for (auto [s, t] : std::vector<std::pair<int, int>>{{0, 2}, {0, 3}, {0, 4}, {1, 2}, {1, 3}, {2, 1}, {2, 2}, {3, 1}}) {
        Options o(OptionMap{{"max_depth", "3"}, {"strategy", fmt::format("{},{}", s, t)}});
        const BlockMoments m = block_moments(path, "bdpt", o, 6, 16, 600 + 100 * k++);
        if (sum.mean.empty()) sum = BlockMoments{std::vector<double>(m.mean.size()), std::vector<double>(m.mean.size())};
        for (size_t b = 0; b < m.mean.size(); ++b) sum.mean[b] += m.mean[b], sum.var[b] += m.var[b];
    }
    expect_same_image(whole, sum, "sum of the MIS-weighted strategy images");
}

TEST(BDPT, EachUnweightedStrategyEstimatesDirectLight) {
    // Direct light only (max_depth 2) with the emitters hidden: paths of exactly two edges, which the
    // camera path hitting the light (0, 3), next event estimation (1, 2) and light tracing (2, 1) can
    // each sample on their own, unweighted.
    const std::string path = write_temp_scene(kGlossyRoomXml);
    const OptionMap direct{{"max_depth", "2"}, {"hide_emitters", "true"}};
    const BlockMoments ref = block_moments(path, "path", Options(direct), 6, 64, 700);
    int k = 0;
    for (const char *st : {"0,3", "1,2", "2,1"}) {
        OptionMap o = direct;
        o["strategy"] = st;
        o["strategy_weight"] = "none";
        expect_same_image(ref, block_moments(path, "bdpt", Options(o), 6, st[0] == '0' ? 128 : 48, 800 + 100 * k++),
                          std::string("unweighted strategy ") + st);
    }
}

// A surface seen from above and lit at a slant by a small sphere light, in a scene file of its own.
std::string slanted_light_scene(const std::string &surface) {
    return write_temp_scene(R"(<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0,2.2,2.2" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>
)" + surface + R"(
  <shape type="sphere"><point name="center" x="-2" y="1.2" z="-0.5"/><float name="radius" value="0.3"/>
    <emitter type="area"><rgb name="radiance" value="20"/></emitter></shape>
</scene>)");
}

// A quad whose vertex normals lean away from its face normal: shading normals make the BSDF's adjoint
// differ from the BSDF (Veach §5.3). Light tracing without the correction renders it visibly darker or
// brighter than path tracing (the bug of pbrt-v4 issues #13 and #385).
std::string tilted_normals_scene() {
    const std::string scene = slanted_light_scene(R"(  <shape type="obj"><string name="filename" value="quad.obj"/>
    <bsdf type="roughplastic"><float name="alpha" value="0.4"/><rgb name="diffuse_reflectance" value="0.7"/></bsdf></shape>)");
    std::ofstream(std::filesystem::path(scene).parent_path() / "quad.obj")
        << "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
           "vn -0.5 1 0\nvn 0.5 1 0.3\nvn 0.6 1 0\nvn -0.4 1 -0.5\n"
           "f 1//1 4//4 3//3\nf 1//1 3//3 2//2\n";
    return scene;
}

TEST(LightTracer, CorrectsForShadingNormals) {
    const std::string path = tilted_normals_scene();
    const OptionMap o{{"max_depth", "2"}, {"hide_emitters", "true"}};
    const BlockMoments ref = block_moments(path, "path", Options(o), 6, 64, 900);
    expect_same_image(ref, block_moments(path, "light", Options(o), 6, 64, 1000), "light tracing, shading normals");
    expect_same_image(ref, block_moments(path, "bdpt", Options(o), 6, 32, 1100), "bdpt, shading normals");
}

// The same with a bump map: its BSDF's shading normal is the perturbed one, not the hit's (light tracing
// and BDPT rendered such a block 9 % and 23 % brighter than path tracing before the bump map corrected
// for it). A height field that rises along u, tilting the normal by ~45° over the whole plane.
std::string bump_mapped_scene() {
    const std::string scene = slanted_light_scene(R"(  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/></transform>
    <bsdf type="bumpmap">
      <texture name="map" type="bitmap"><string name="filename" value="ramp.exr"/><boolean name="raw" value="true"/></texture>
      <float name="scale" value="2"/>
      <bsdf type="roughplastic"><float name="alpha" value="0.2"/><rgb name="diffuse_reflectance" value="0.6"/></bsdf>
    </bsdf></shape>)");
    Image ramp(32, 32, 3);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            for (int c = 0; c < 3; ++c) ramp.at(x, y, c) = float(x) / 32.f;
    write_exr((std::filesystem::path(scene).parent_path() / "ramp.exr").string(), ramp);
    return scene;
}

TEST(LightTracer, CorrectsForBumpMappedShadingNormals) {
    const std::string path = bump_mapped_scene();
    const OptionMap o{{"max_depth", "3"}, {"hide_emitters", "true"}};
    const BlockMoments ref = block_moments(path, "path", Options(o), 6, 64, 1500);
    expect_same_image(ref, block_moments(path, "light", Options(o), 6, 64, 1600), "light tracing, bump map");
    expect_same_image(ref, block_moments(path, "bdpt", Options(o), 6, 32, 1700), "bdpt, bump map");
}

// Lights at a point in view of the camera: a point light, and a spot light pointing away from it. No
// camera sees them (Mitsuba's ptracer never connects delta emitters to the sensor; camera paths cannot
// hit them), only the floor they light. Light tracing used to connect their own position to the camera
// and splat their intensity, unshaped by the spot's cone, onto the pixel each projects to: pixels of
// ~1000 in Mitsuba's various_emitters scene, three times its image mean.
std::string lights_at_points_in_view_scene() {
    return write_temp_scene(R"(<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,1.5,4" target="0,0.8,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></shape>
  <emitter type="point"><point name="position" x="-0.8" y="1" z="0"/><rgb name="intensity" value="2"/></emitter>
  <emitter type="spot"><rgb name="intensity" value="4"/><float name="cutoff_angle" value="30"/>
    <transform name="to_world"><lookat origin="0.8,1.2,0" target="0.8,0,0" up="0,0,1"/></transform></emitter>
</scene>)");
}

TEST(LightTracer, NoCameraSeesALightAtAPoint) {
    const std::string path = lights_at_points_in_view_scene();
    const BlockMoments ref = block_moments(path, "path", Options(), 6, 32, 1800);
    expect_same_image(ref, block_moments(path, "light", Options(), 6, 32, 1900), "light tracing, point and spot light in view");
    expect_same_image(ref, block_moments(path, "bdpt", Options(), 6, 16, 2000), "bdpt, point and spot light in view");
}

// NEE++ selection is unbiased whatever the map says: planted "never visible" for every pair, with
// learning off, so the selection leans on wrong scores for the whole render.
// wrong_map: every pair of the scene's grid occluded (wrong_map() below), a copy of it for this render.
RenderedImage render_bdpt_with_wrong_map(const std::string &path, int spp, uint64_t seed,
                                         const std::pair<VoxelGrid, VisibilityMap> &wrong_map) {
    auto scene = load_scene(path);
    Options o(OptionMap{{"light_paths", "neepp"}, {"candidates", "8"}, {"pool", "512"}, {"learn", "false"}});
    for (auto &[k, v] : scene->settings.integrator_options) o.set(k, v);  // the scene's max_depth
    auto integ = make_integrator("bdpt", o);
    auto &tester = dynamic_cast<NeeppShadowRays &>(dynamic_cast<BDPTIntegrator &>(*integ).shadow_rays());
    tester.adopt_map(wrong_map.first, wrong_map.second);
    RenderJob job;
    job.spp = spp;
    job.seed = seed;
    RenderResult r = render(*scene, *integ, job);
    return {r.image, r};
}

// A map of the scene's grid that calls every pair occluded, for render_bdpt_with_wrong_map: built once, as
// each render takes a copy of it.
std::pair<VoxelGrid, VisibilityMap> wrong_map(const std::string &path) {
    auto scene = load_scene(path);
    auto integ = make_integrator("bdpt", Options(OptionMap{{"light_paths", "neepp"}}));
    auto &tester = dynamic_cast<NeeppShadowRays &>(dynamic_cast<BDPTIntegrator &>(*integ).shadow_rays());
    VoxelGrid grid(scene->bounds(), tester.options().voxels);
    VisibilityMap map(grid.cell_count());
    for (uint64_t p = 0; p < map.pair_count(); ++p) map.set(p, PairCounts{0, 65535});
    return {grid, std::move(map)};
}

TEST(BDPT, NeeppLightPathSelectionIsUnbiased) {
    const std::string path = write_temp_scene(kGlossyRoomXml);
    const BlockMoments ref = block_moments(path, "bdpt", Options(), 6, 16, 1200);
    // The six renders start from the map the first seeded (common/seeded_map.h).
    Options neepp(
        with_map_file({{"light_paths", "neepp"}, {"candidates", "8"}, {"pool", "512"}}, map_file_beside(path), "bdpt"));
    expect_same_image(ref, block_moments(path, "bdpt", neepp, 6, 16, 1300), "bdpt, NEE++ light-path selection");
    const auto wrong = wrong_map(path);
    std::vector<std::vector<double>> per_seed;
    for (int s = 0; s < 6; ++s)
        per_seed.push_back(block_means(render_bdpt_with_wrong_map(path, 16, 1400 + s, wrong).image, 6, 6));
    expect_same_image(ref, moments_over_seeds(per_seed), "bdpt, NEE++ selection over a wrong map");
}

TEST(BDPT, SameImageToTheBitForASeed) {
    const std::string path = write_temp_scene(kGlossyRoomXml);
    for (const char *integrator : {"bdpt", "light"})
        for (bool neepp : {false, true}) {
            if (neepp && std::string(integrator) == "light") continue;
            Options o = neepp ? Options(OptionMap{{"light_paths", "neepp"}, {"pool", "256"}}) : Options();
            auto a = render_scene_file(path, 8, 5, o, integrator);
            auto b = render_scene_file(path, 8, 5, o, integrator);
            ASSERT_EQ(a.image.data.size(), b.image.data.size());
            EXPECT_EQ(0, std::memcmp(a.image.data.data(), b.image.data.data(), a.image.data.size() * sizeof(float)))
                << integrator << (neepp ? " with NEE++ selection" : "");
            EXPECT_GT(a.result.counters.splats, 0u) << integrator;
        }
}

TEST(BDPT, RefusesMalformedOptions) {
    for (const OptionMap &o : std::vector<OptionMap>{{{"strategy", "1"}}, {{"strategy", "a,b"}}, {{"strategy", "1,0"}},
                                                     {{"strategy_weight", "maybe"}, {"strategy", "1,2"}},
                                                     {{"mis", "max"}}, {{"light_paths", "many"}},
                                                     {{"light_paths", "neepp"}, {"candidates", "0"}},
                                                     {{"candidates", "4"}}, {{"max_depth", "0"}}})
        EXPECT_THROW(make_integrator("bdpt", Options(o)), std::invalid_argument) << o.begin()->first;
    EXPECT_THROW(make_integrator("light", Options(OptionMap{{"strategy", "1,1"}})), std::invalid_argument);
}

}  // namespace
