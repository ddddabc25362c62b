// Analytic furnace scenes, rendered by every path-integrator mode. Inside a closed sphere whose inner
// surface is diffuse with albedo rho and emits Le, every ray sees L = Le * sum_{k < max_depth} rho^k
// (Le / (1 - rho) unbounded): this checks emission, NEE, MIS, Russian roulette and max_depth at once.
#include <gtest/gtest.h>
#include <fmt/core.h>
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

std::string inner_furnace_xml(float rho, float le, int max_depth) {
    return fmt::format(R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="{max_depth}"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,0,0" target="0,0,1" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <shape type="sphere">
    <float name="radius" value="2"/>
    <boolean name="flip_normals" value="true"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="{rho}"/></bsdf>
    <emitter type="area"><rgb name="radiance" value="{le}"/></emitter>
  </shape>
</scene>)",
                       fmt::arg("max_depth", max_depth), fmt::arg("rho", rho), fmt::arg("le", le));
}

double expected_furnace(float rho, float le, int max_depth) {
    if (max_depth < 0) return le / (1 - rho);
    double s = 0, p = 1;
    for (int k = 0; k < max_depth; ++k, p *= rho) s += p;
    return le * s;
}

struct FurnaceCase {
    std::string name;
    std::map<std::string, std::string> options;
    std::string sampler = "independent";
    std::string integrator = "path";
};

void PrintTo(const FurnaceCase &c, std::ostream *os) { *os << c.name; }

class Furnace : public ::testing::TestWithParam<FurnaceCase> {};

TEST_P(Furnace, InnerSphereMatchesGeometricSeries) {
    const float rho = 0.7f, le = 0.5f;
    for (int max_depth : {1, 2, 3, 8, -1}) {
        std::string path = write_temp_scene(inner_furnace_xml(rho, le, max_depth));
        auto out = render_scene_file(path, 64, 7, Options(GetParam().options), GetParam().integrator, GetParam().sampler);
        double expected = expected_furnace(rho, le, max_depth);
        auto st = pixel_statistics(out.image, 1);
        // max_depth 1 and 2 are deterministic up to float rounding and the ray offset; deeper paths are
        // noisy. A bounce's rays start ray_epsilon(p) = 2.7e-4 off the sphere (Mitsuba's offset), which
        // leaves the image 1.1e-4 (max_depth 2) to 1.4e-4 (max_depth 3) low at 65536 spp (3e-5 with an
        // offset 9x smaller): the allowance covers that.
        double tol = 5 * st.stderr_ + 3e-4 * expected;
        EXPECT_NEAR(st.mean, expected, tol) << GetParam().name << " max_depth=" << max_depth;
    }
}

INSTANTIATE_TEST_SUITE_P(PathModes, Furnace,
                         ::testing::Values(FurnaceCase{"nee_power", {{"light_sampler", "power"}}},
                                           FurnaceCase{"nee_uniform", {{"light_sampler", "uniform"}}},
                                           FurnaceCase{"bsdf_only", {{"nee", "false"}}},
                                           FurnaceCase{"rr_early", {{"rr_depth", "1"}}},
                                           FurnaceCase{"sobol_sampler", {}, "sobol"},
                                           FurnaceCase{"guided", {{"guiding", "sdtree"}}},
                                           FurnaceCase{"guided_bsdf_only", {{"guiding", "sdtree"}, {"nee", "false"}}},
                                           // The map's guide reads the visibility map, whose seeding traces
                                           // samples_per_pair rays for every pair of a shading voxel and a light
                                           // voxel: in a sphere that emits everywhere, every pair of its ~1500
                                           // voxels, 90 % of these cases' time at the default 16. One sample
                                           // per pair is a prior as good for a furnace.
                                           FurnaceCase{"map_guided", {{"guiding", "map"}, {"samples_per_pair", "1"}}},
                                           FurnaceCase{"map_guided_bsdf_only", {{"guiding", "map"}, {"nee", "false"}, {"samples_per_pair", "1"}}},
                                           FurnaceCase{"both_guided", {{"guiding", "sdtree+map"}, {"samples_per_pair", "1"}}},
                                           FurnaceCase{"bdpt", {}, "independent", "bdpt"},
                                           FurnaceCase{"bdpt_balance", {{"mis", "balance"}}, "independent", "bdpt"},
                                           FurnaceCase{"bdpt_neepp", {{"light_paths", "neepp"}, {"pool", "512"}, {"candidates", "4"}},
                                                       "independent", "bdpt"},
                                           FurnaceCase{"light", {}, "independent", "light"}),
                         [](const auto &info) { return info.param.name; });

// A convex diffuse object under a constant environment of radiance 1 reflects exactly its albedo.
TEST(Furnace, DiffuseSphereUnderConstantEnvironment) {
    for (const char *integrator : {"path", "path_bsdf", "bdpt", "light"}) {
        const bool nee = std::string(integrator) != "path_bsdf";
        std::string xml = R"(<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="10"/>
    <transform name="to_world"><lookat origin="0,0,-10" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
  </sensor>
  <shape type="sphere"><float name="radius" value="1.5"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.3, 0.9"/></bsdf></shape>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
</scene>)";
        const std::string name = nee ? integrator : "path";
        Options o(OptionMap{{"max_depth", "2"}});
        if (name == "path") o.set("nee", nee ? "true" : "false");
        auto out = render_scene_file(write_temp_scene(xml), 256, 3, o, name);
        // The 8x8 image at fov 10 from distance 10 sees only the sphere (half-width 0.87 < 1.5).
        const float expected[3] = {0.6f, 0.3f, 0.9f};
        for (int c = 0; c < 3; ++c) {
            auto st = pixel_statistics(out.image, c);
            EXPECT_NEAR(st.mean, expected[c], 5 * st.stderr_ + 1e-4) << integrator << " channel " << c;
        }
    }
}

// The sky the camera sees directly is the environment's radiance in every integrator, light tracing
// included (no light path can reach a pinhole from the sky: its camera ray has to find it).
TEST(Furnace, ConstantEnvironmentSeenDirectly) {
    const std::string xml = R"(<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,0,-10" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <shape type="sphere"><float name="radius" value="1"/><bsdf type="diffuse"/></shape>
  <emitter type="constant"><rgb name="radiance" value="0.25, 0.5, 2"/></emitter>
</scene>)";
    for (const char *integrator : {"path", "bdpt", "light"}) {
        auto out = render_scene_file(write_temp_scene(xml), 4, 3, Options(OptionMap{{"max_depth", "3"}}), integrator);
        for (auto [x, y] : {std::pair{0, 0}, {15, 0}, {0, 15}, {15, 15}, {7, 0}})  // corners and an edge: sky only
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(out.image.at(x, y, c), c == 0 ? 0.25f : c == 1 ? 0.5f : 2.f, 1e-5f)
                    << integrator << " pixel " << x << "," << y << " channel " << c;
        // With hide_emitters the sky is black, in light tracing as in the others.
        auto hidden = render_scene_file(write_temp_scene(xml), 1, 3,
                                        Options(OptionMap{{"max_depth", "3"}, {"hide_emitters", "true"}}), integrator);
        EXPECT_EQ(hidden.image.at(0, 0, 2), 0.f) << integrator;
    }
}

}  // namespace
