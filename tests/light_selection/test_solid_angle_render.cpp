// Solid-angle sampling of area lights renders the image area sampling renders (per-block z-tests over
// independent seeds): a room lit by a textured rectangle close to the ceiling and a sphere light near a
// wall, under the path tracer's two forms, volpath and bdpt.
#include <gtest/gtest.h>

#include "light_test_scenes.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

const std::string &scene_path() {
    static const std::string path = write_temp_scene(lamps_xml(), "lamps.xml");
    return path;
}

// Area sampling of a light this close has heavy tails: few seeds underestimate its variance.
constexpr int kSeeds = 8, kSpp = 32;

BlockMoments moments(const std::string &integrator, OptionMap o, uint64_t seed0) {
    return block_moments(scene_path(), integrator, Options(o), kSeeds, kSpp, seed0);
}

TEST(SolidAngleRender, PathFastFormAgreesWithAreaSampling) {
    const BlockMoments area = moments("path", {}, 101);
    const BlockMoments solid = moments("path", {{"area_light_sampling", "solid-angle"}}, 202);
    expect_same_image(area, solid, "path, fast form");
    // The point of it: less noise, summed over the blocks, on a scene of lights this close.
    double v_area = 0, v_solid = 0;
    for (size_t b = 0; b < area.var.size(); ++b) v_area += area.var[b], v_solid += solid.var[b];
    EXPECT_LT(v_solid, v_area) << "block variance: area " << v_area << ", solid angle " << v_solid;
}

TEST(SolidAngleRender, PathReferenceFormAgreesWithAreaSampling) {
    expect_same_image(moments("path", {{"form", "reference"}}, 303),
                      moments("path", {{"form", "reference"}, {"area_light_sampling", "solid-angle"}}, 404),
                      "path, reference form");
}

TEST(SolidAngleRender, ResampledNeeAgreesWithAreaSampling) {
    expect_same_image(moments("path", {}, 505), moments("path", {{"area_light_sampling", "solid-angle"}, {"ris", "4"}}, 606),
                      "path, ris=4");
}

TEST(SolidAngleRender, VolpathAgreesWithAreaSampling) {
    expect_same_image(moments("volpath", {}, 707), moments("volpath", {{"area_light_sampling", "solid-angle"}}, 808),
                      "volpath");
}

TEST(SolidAngleRender, BdptAgreesWithAreaSampling) {
    expect_same_image(moments("bdpt", {}, 909), moments("bdpt", {{"area_light_sampling", "solid-angle"}}, 1010), "bdpt");
}

TEST(SolidAngleRender, OptionIsCheckedAndDescribed) {
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"area_light_sampling", "cone"}})), std::invalid_argument);
    EXPECT_THROW(make_integrator("bdpt", Options(OptionMap{{"area_light_sampling", "spherical"}})), std::invalid_argument);
    // The light tracer samples no light from a point: the option means nothing there.
    EXPECT_THROW(make_integrator("light", Options(OptionMap{{"area_light_sampling", "solid-angle"}})), std::invalid_argument);
    auto path = make_integrator("path", Options(OptionMap{{"area_light_sampling", "solid-angle"}}));
    EXPECT_EQ(path->describe()["area_light_sampling"], "solid-angle");
    auto bdpt = make_integrator("bdpt", Options());
    EXPECT_EQ(bdpt->describe()["area_light_sampling"], "area");
}

}  // namespace
