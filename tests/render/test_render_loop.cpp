// The render loop: sample counts, time limits and cancellation, always ending with an image.
#include <gtest/gtest.h>
#include <atomic>
#include <thread>
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

std::unique_ptr<Scene> demo_scene(int w, int h) {
    return load_scene(std::string(NEEPP_SOURCE_DIR) + "/scenes/door-ajar/scene.xml",
                      {{"resx", std::to_string(w)}, {"resy", std::to_string(h)}});
}

TEST(RenderLoop, ReachesTheSampleCountInPasses) {
    auto scene = demo_scene(32, 18);
    for (const char *policy : {"nee", "neepp"}) {
        SCOPED_TRACE(policy);
        Options options(scene->settings.integrator_options);
        options.set("shadow_rays", policy);
        auto integ = make_integrator("path", options);
        RenderJob job;
        job.spp = 37;
        RenderResult r = render(*scene, *integ, job);
        EXPECT_EQ(r.spp, 37);
        EXPECT_EQ(r.stopped_by, "spp");
        if (integ->learns_between_passes())
            EXPECT_GT(r.passes, 3);  // small first passes, so per-pass hooks (NEE++) learn early
        else
            EXPECT_EQ(r.passes, 3);  // else 1 spp, then full passes (32 + 4): packets of rays from one pixel
        EXPECT_EQ(r.counters.rays >= uint64_t(37 * 32 * 18), true);
        EXPECT_GT(pixel_statistics(r.image, 0).mean, 0.0);
    }
}

TEST(RenderLoop, OnlyAnIntegratorWithAVisibilityMapLearnsBetweenPasses) {
    auto scene = demo_scene(32, 18);
    auto learns = [&](const OptionMap &o) {
        auto integ = make_integrator("path", Options(o));
        integ->prepare(*scene);
        return integ->learns_between_passes();
    };
    EXPECT_FALSE(learns({{"shadow_rays", "nee"}}));
    EXPECT_TRUE(learns({{"shadow_rays", "neepp"}}));
}

TEST(RenderLoop, NeeppWithRejectionOffRendersAsNee) {
    // Rejection turned off after the first pass (fewer than all of its shadow rays occluded): the policy
    // then learns nothing, so it gets nee's full passes, and with them nee's image to the bit.
    auto scene = demo_scene(32, 18);
    RenderJob job;
    job.spp = 37;
    auto nee = make_integrator("path", Options(OptionMap{{"shadow_rays", "nee"}}));
    const RenderResult a = render(*scene, *nee, job);
    for (const char *policy : {"neepp", "neepp-adaptive", "neepp-cv"}) {
        SCOPED_TRACE(policy);
        auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", policy}, {"min_occluded", "1"}}));
        const RenderResult b = render(*scene, *integ, job);
        EXPECT_FALSE(integ->learns_between_passes());
        EXPECT_EQ(b.passes, a.passes);
        EXPECT_EQ(b.passes, 3);
        ASSERT_EQ(b.image.data.size(), a.image.data.size());
        EXPECT_TRUE(b.image.data == a.image.data);
    }
}

TEST(RenderLoop, TimeLimitUsesTheBudgetAndStops) {
    auto scene = demo_scene(64, 36);
    auto integ = make_integrator("path", Options(scene->settings.integrator_options));
    RenderJob job;
    job.spp = 0;
    job.time_limit_s = 0.6;
    RenderResult r = render(*scene, *integ, job);
    EXPECT_EQ(r.stopped_by, "time");
    EXPECT_GE(r.spp, 1);
    EXPECT_LT(r.render_time_s, 0.6 * 1.3);
    // Passes are sized to fit: most of the budget turns into samples (none thrown away by a cut-off pass).
    EXPECT_GT(r.render_time_s, 0.6 * 0.5);
}

TEST(RenderLoop, CancelStopsEarlyWithTheImageSoFar) {
    auto scene = demo_scene(64, 36);
    auto integ = make_integrator("path", Options(scene->settings.integrator_options));
    std::atomic<bool> cancel{false};
    RenderJob job;
    job.spp = 1 << 20;
    job.cancel = &cancel;
    std::thread stopper([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        cancel = true;
    });
    RenderResult r = render(*scene, *integ, job);
    stopper.join();
    EXPECT_EQ(r.stopped_by, "cancel");
    EXPECT_LT(r.spp, 1 << 20);
    EXPECT_EQ(r.image.width, 64);
    EXPECT_GT(pixel_statistics(r.image, 0).mean, 0.0);
}

TEST(RenderLoop, ShowsTheImageBetweenPassesAndTheFinalOneWithoutChangingIt) {
    auto scene = demo_scene(32, 18);
    RenderJob job;
    job.spp = 37;
    auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", "nee"}}));
    const RenderResult plain = render(*scene, *integ, job);
    ASSERT_EQ(plain.passes, 3);  // 1 + 32 + 4 spp
    for (double interval : {0.0, 1e9}) {
        SCOPED_TRACE(interval);
        std::vector<Image> shown;
        job.display_interval_s = interval;
        job.on_display = [&](Image image) { shown.push_back(std::move(image)); };
        const RenderResult r = render(*scene, *integ, job);
        // Every pass but the last (whose image is the final one), or only the first when the interval is
        // long; then the final image.
        ASSERT_EQ(shown.size(), interval == 0 ? 3u : 2u);
        EXPECT_TRUE(shown.back().data == r.image.data);
        EXPECT_FALSE(shown.front().data == r.image.data);  // one pass: fewer samples
        EXPECT_TRUE(r.image.data == plain.image.data);     // the hook only reads
    }
}

TEST(RenderLoop, NeedsASampleCountOrATimeLimit) {
    auto scene = demo_scene(8, 8);
    auto integ = make_integrator("path", Options());
    RenderJob job;
    job.spp = 0;
    EXPECT_THROW(render(*scene, *integ, job), std::invalid_argument);
}

}  // namespace
