// PSSMLT converges to what path tracing renders (pbrt-v4's MLT renders dark, its issue #139, and
// converges to seed-dependent images, #525: both would fail here), over BDPT and over the path tracer,
// with NEE++'s roulette inside the chain, and renders the same image to the bit for a seed whatever the
// number of threads.
#include <gtest/gtest.h>
#include <cstring>
#include "neepp/integrators/pssmlt.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// Chains and bootstrap sized for the tests' 24 x 18 films.
OptionMap mlt(OptionMap extra = {}) {
    extra.emplace("chains", "32");
    extra.emplace("bootstrap", "20000");
    return extra;
}

TEST(PSSMLT, AgreesWithPathTracingOnAGlossyRoom) {
    const std::string path = write_temp_scene(kGlossyRoomXml);
    const BlockMoments ref = block_moments(path, "path", Options(), 6, 64, 100);
    expect_same_image(ref, block_moments(path, "pssmlt", Options(mlt()), 6, 64, 200), "pssmlt over bdpt");
    expect_same_image(ref, block_moments(path, "pssmlt", Options(mlt({{"bidirectional", "false"}})), 6, 64, 300),
                      "pssmlt over the path tracer");
}

TEST(PSSMLT, AgreesWithPathTracingWithNeeppRouletteInTheChain) {
    const std::string path = write_temp_scene(kGlossyRoomXml);
    const BlockMoments ref = block_moments(path, "path", Options(), 6, 64, 400);
    // The map learns between passes: the chains' states are evaluated again under each new map.
    expect_same_image(ref, block_moments(path, "pssmlt", Options(mlt({{"shadow_rays", "neepp"}})), 6, 64, 500),
                      "pssmlt over bdpt, NEE++ roulette");
}

TEST(PSSMLT, ImageMeanIsTheNormalization) {
    // Every mutation records contributions whose luminance adds up to one, scaled by b: the image's mean
    // luminance is b, the mean of f over the bootstrap and the large steps (box filter: nothing leaves
    // the film).
    const std::string path = write_temp_scene(kGlossyRoomXml);
    auto scene = load_scene(path);
    Options o(mlt());
    o.set("max_depth", "6");
    auto integ = make_integrator("pssmlt", o);
    RenderJob job;
    job.spp = 16;
    const RenderResult r = render(*scene, *integ, job);
    double lum = 0;
    const size_t n = size_t(r.image.width) * r.image.height;
    for (size_t i = 0; i < n; ++i)
        lum += luminance(Color(r.image.data[3 * i], r.image.data[3 * i + 1], r.image.data[3 * i + 2]));
    const double b = dynamic_cast<PSSMLTIntegrator &>(*integ).normalization();
    EXPECT_GT(b, 0.01);
    EXPECT_NEAR(lum / double(n), b, 1e-4 * b);
}

TEST(PSSMLT, SameImageToTheBitForASeedWhateverTheThreads) {
    const std::string path = write_temp_scene(kGlossyRoomXml);
    auto scene = load_scene(path);
    std::vector<float> first;
    for (int threads : {1, 2, 2}) {
        auto integ = make_integrator("pssmlt", Options(mlt({{"max_depth", "6"}})));
        RenderJob job;
        job.spp = 8;
        job.seed = 9;
        job.threads = threads;
        const RenderResult r = render(*scene, *integ, job);
        if (first.empty()) {
            first = r.image.data;
            continue;
        }
        ASSERT_EQ(first.size(), r.image.data.size());
        EXPECT_EQ(0, std::memcmp(first.data(), r.image.data.data(), first.size() * sizeof(float))) << threads << " threads";
    }
    auto other = make_integrator("pssmlt", Options(mlt({{"max_depth", "6"}})));
    RenderJob job;
    job.spp = 8;
    job.seed = 10;
    EXPECT_NE(0, std::memcmp(first.data(), render(*scene, *other, job).image.data.data(), first.size() * sizeof(float)))
        << "another seed renders another image";
}

TEST(PSSMLT, RefusesWhatAChainCannotSample) {
    for (const OptionMap &o : std::vector<OptionMap>{{{"shadow_rays", "neepp-cv"}},
                                                     {{"light_paths", "neepp"}},
                                                     {{"chains", "0"}},
                                                     {{"bootstrap", "0"}},
                                                     {{"large_step", "1.5"}},
                                                     {{"sigma", "0"}},
                                                     {{"no_such_option", "1"}}})
        EXPECT_THROW(make_integrator("pssmlt", Options(o)), std::invalid_argument) << o.begin()->first;
    try {
        make_integrator("pssmlt", Options(OptionMap{{"no_such_option", "1"}}));
    } catch (const std::invalid_argument &e) {
        EXPECT_NE(std::string(e.what()).find("no_such_option"), std::string::npos) << e.what();
    }
}

}  // namespace
