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

struct Moments {
    std::vector<double> mean, var;  // per block, over seeds
};

// Block means (4x3 blocks of the image, green channel) per seed, then their mean and variance of the mean.
Moments block_moments(const std::string &path, const Options &o, int seeds, int spp) {
    const int bx = 6, by = 6;
    std::vector<std::vector<double>> per_seed;
    for (int s = 0; s < seeds; ++s) {
        Image img = render_scene_file(path, spp, 1000 + s * 17 + (o.get_bool("nee", true) ? 0 : 5), o).image;
        std::vector<double> blocks;
        for (int y0 = 0; y0 < img.height; y0 += by)
            for (int x0 = 0; x0 < img.width; x0 += bx) {
                double sum = 0;
                for (int y = y0; y < y0 + by; ++y)
                    for (int x = x0; x < x0 + bx; ++x) sum += img.at(x, y, 1);
                blocks.push_back(sum / (bx * by));
            }
        per_seed.push_back(blocks);
    }
    Moments m;
    size_t nb = per_seed[0].size();
    m.mean.assign(nb, 0);
    m.var.assign(nb, 0);
    for (size_t b = 0; b < nb; ++b) {
        for (auto &ps : per_seed) m.mean[b] += ps[b] / seeds;
        for (auto &ps : per_seed) m.var[b] += (ps[b] - m.mean[b]) * (ps[b] - m.mean[b]) / (seeds - 1);
        m.var[b] /= seeds;
    }
    return m;
}

TEST(PathIntegrator, NeeMisAgreesWithBsdfSampling) {
    std::string path = write_temp_scene(kRoomXml);
    Moments nee = block_moments(path, Options(OptionMap{{"nee", "true"}}), 6, 48);
    Moments bsdf = block_moments(path, Options(OptionMap{{"nee", "false"}}), 6, 96);
    size_t nb = nee.mean.size();
    // Bonferroni over the blocks at a 1e-3 family-wise level: |z| < 3.9 for 12 blocks (t with 5 dof is
    // heavier-tailed, so use a generous bound of 5).
    double overall_nee = 0, overall_bsdf = 0, var_nee = 0, var_bsdf = 0;
    for (size_t b = 0; b < nb; ++b) {
        double z = (nee.mean[b] - bsdf.mean[b]) / std::sqrt(nee.var[b] + bsdf.var[b] + 1e-12);
        EXPECT_LT(std::abs(z), 5.0) << "block " << b << " nee " << nee.mean[b] << " bsdf " << bsdf.mean[b];
        overall_nee += nee.mean[b] / nb; overall_bsdf += bsdf.mean[b] / nb;
        var_nee += nee.var[b] / (nb * nb); var_bsdf += bsdf.var[b] / (nb * nb);
    }
    double z = (overall_nee - overall_bsdf) / std::sqrt(var_nee + var_bsdf);
    EXPECT_LT(std::abs(z), 4.0) << "image mean nee " << overall_nee << " bsdf " << overall_bsdf;
    EXPECT_GT(overall_nee, 0.01);  // the scene is lit: a black image would pass the z-test trivially
}

}  // namespace
