// Rays leave a surface offset by Mitsuba 3's epsilon (kRayEpsilon), and scenes made for Mitsuba rely on
// it: bathroom's light bulbs are glass shells modelled twice, 6e-5 apart, and Mitsuba's rays step over the
// second shell. A light seen through two thin glass panes shows which.
#include <gtest/gtest.h>
#include <fmt/core.h>
#include "neepp/materials/fresnel.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// A camera looking at a black area light of radiance 1 through two thin glass panes, gap apart.
double light_through_two_panes(float gap) {
    const std::string xml = scene_header_xml(-1, 16, "0,0,3", "0,0,0", 8, 8) + fmt::format(R"(
  <bsdf type="thindielectric" id="glass"/>
  <shape type="rectangle"><ref id="glass"/></shape>
  <shape type="rectangle"><transform name="to_world"><translate z="{}"/></transform><ref id="glass"/></shape>
  <shape type="rectangle">
    <transform name="to_world"><scale value="2"/><translate z="-1"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
    <emitter type="area"><rgb name="radiance" value="1"/></emitter>
  </shape>
</scene>)", -gap);
    auto out = render_scene_file(write_temp_scene(xml), 256, 3, Options{});
    return pixel_statistics(out.image, 0).mean;
}

}  // namespace

TEST(RayOffset, MatchesMitsubasEpsilon) {
    EXPECT_FLOAT_EQ(kRayEpsilon, 1500.f * 0x1p-24f);
    EXPECT_FLOAT_EQ(ray_epsilon(Vec3(0.5f, -2.f, 1.f)), 3.f * kRayEpsilon);
}

TEST(RayOffset, StepsOverAPaneCloserThanTheOffset) {
    // A pane transmits 1 - R', R' = 2r / (1 + r) its slab reflectance (r = 0.04 for glass at normal
    // incidence; the 8 degrees off-axis of the view change it by < 1e-4).
    const float r = fresnel_dielectric(1.f, 1.5f).r, R = 2 * r / (1 + r), T = 1 - R;
    // The panes 5e-5 apart (the offset is ~1e-4 there): the ray leaving the first pane starts beyond the
    // second, so the light shows through one pane, as in Mitsuba.
    EXPECT_NEAR(light_through_two_panes(5e-5f), T, 0.01);
    // 0.01 apart: both panes, and the light bouncing between them, T^2 / (1 - R^2).
    EXPECT_NEAR(light_through_two_panes(1e-2f), T * T / (1 - R * R), 0.01);
}
