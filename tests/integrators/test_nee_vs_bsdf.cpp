// Next event estimation with MIS and pure BSDF sampling estimate the same integral: on a small closed
// room with an occluder and glossy, specular and textured materials their images must agree within
// the noise (a two-sample z-test on the image means and on coarse blocks, with independent seeds).
#include <gtest/gtest.h>
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

const char *kRoomXml = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,1,1.9" target="0,0.8,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></bsdf>
  <bsdf type="twosided" id="checker"><bsdf type="diffuse">
    <texture name="reflectance" type="checkerboard"><rgb name="color0" value="0.8,0.2,0.2"/><rgb name="color1" value="0.2,0.2,0.8"/></texture>
  </bsdf></bsdf>
  <shape type="cube"><transform name="to_world"><scale value="2"/><translate y="1"/></transform>
    <bsdf type="twosided"><bsdf type="roughplastic"><float name="alpha" value="0.3"/><string name="distribution" value="ggx"/>
      <rgb name="diffuse_reflectance" value="0.5,0.6,0.4"/></bsdf></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.4"/><translate x="-0.5" y="0.4" z="-0.3"/></transform><ref id="checker"/></shape>
  <shape type="sphere"><point name="center" x="0.6" y="0.5" z="0.3"/><float name="radius" value="0.4"/>
    <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.2"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="2.9"/></transform>
    <ref id="white"/><emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.8" y="0.8"/><rotate x="1" angle="90"/><translate y="2.2"/></transform><ref id="white"/></shape>
</scene>)";

BlockMoments block_moments(const std::string &path, const Options &o, int seeds, int spp) {
    std::vector<std::vector<double>> per_seed;
    for (int s = 0; s < seeds; ++s)
        per_seed.push_back(block_means(render_scene_file(path, spp, 1000 + s * 17 + (o.get_bool("nee", true) ? 0 : 5), o).image, 6, 6));
    return moments_over_seeds(per_seed);
}

TEST(PathIntegrator, NeeMisAgreesWithBsdfSampling) {
    std::string path = write_temp_scene(kRoomXml);
    BlockMoments nee = block_moments(path, Options(OptionMap{{"nee", "true"}}), 6, 48);
    BlockMoments bsdf = block_moments(path, Options(OptionMap{{"nee", "false"}}), 6, 96);
    expect_same_image(bsdf, nee, "NEE+MIS against BSDF sampling");
}

}  // namespace
