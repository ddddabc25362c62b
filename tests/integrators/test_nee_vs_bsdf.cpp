// Next event estimation with MIS and pure BSDF sampling estimate the same integral: on a small closed
// room with an occluder and glossy, specular and textured materials their images must agree within
// the noise (a two-sample z-test on the image means and on coarse blocks, with independent seeds).
#include <gtest/gtest.h>
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

BlockMoments block_moments(const std::string &path, const Options &o, int seeds, int spp) {
    std::vector<std::vector<double>> per_seed;
    for (int s = 0; s < seeds; ++s)
        per_seed.push_back(block_means(render_scene_file(path, spp, 1000 + s * 17 + (o.get_bool("nee", true) ? 0 : 5), o).image, 6, 6));
    return moments_over_seeds(per_seed);
}

TEST(PathIntegrator, NeeMisAgreesWithBsdfSampling) {
    std::string path = write_temp_scene(kGlossyRoomXml);
    BlockMoments nee = block_moments(path, Options(OptionMap{{"nee", "true"}}), 6, 48);
    BlockMoments bsdf = block_moments(path, Options(OptionMap{{"nee", "false"}}), 6, 96);
    expect_same_image(bsdf, nee, "NEE+MIS against BSDF sampling");
}

}  // namespace
