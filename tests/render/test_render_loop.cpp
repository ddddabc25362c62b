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
        std::vector<DisplayFrame> shown;
        job.display_interval_s = interval;
        job.on_display = [&](DisplayFrame frame) { shown.push_back(std::move(frame)); };
        const RenderResult r = render(*scene, *integ, job);
        // Every pass but the last (whose image is the final one), or only the first when the interval is
        // long; then the final image.
        ASSERT_EQ(shown.size(), interval == 0 ? 3u : 2u);
        EXPECT_TRUE(shown.back().image.data == r.image.data);
        EXPECT_FALSE(shown.front().image.data == r.image.data);  // one pass: fewer samples
        EXPECT_TRUE(r.image.data == plain.image.data);           // the hook only reads
        // Each frame says what made it: the samples so far and their counters, growing to the result's.
        EXPECT_EQ(shown.front().spp, 1);
        EXPECT_FALSE(shown.front().final);
        EXPECT_GT(shown.front().counters.rays, 0u);
        EXPECT_LT(shown.front().counters.rays, r.counters.rays);
        EXPECT_TRUE(shown.back().final);
        EXPECT_EQ(shown.back().spp, r.spp);
        EXPECT_EQ(shown.back().counters.rays, r.counters.rays);
        EXPECT_DOUBLE_EQ(shown.back().render_time_s, r.render_time_s);
        if (interval == 0) {
            EXPECT_EQ(shown[1].spp, 33);
        }
    }
}

TEST(RenderLoop, AnInteractiveViewGetsPassesOfItsDisplayInterval) {
    // neepp view shows the image a few times a second: a pass longer than that would hold it back. With a
    // cap far below a pass's time, every pass is one sample per pixel; the image is a full render's.
    auto scene = demo_scene(32, 18);
    RenderJob job;
    job.spp = 6;
    auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", "nee"}}));
    const RenderResult plain = render(*scene, *integ, job);
    EXPECT_EQ(plain.passes, 2);  // 1 + 5
    job.max_pass_s = 1e-9;
    const RenderResult capped = render(*scene, *integ, job);
    EXPECT_EQ(capped.passes, 6);
    EXPECT_EQ(capped.spp, 6);
    job.max_pass_s = 1e9;  // a cap longer than any pass changes nothing
    EXPECT_EQ(render(*scene, *integ, job).passes, 2);
}

TEST(RenderLoop, APreparedIntegratorKeepsWhatItLearned) {
    // neepp view restarts the image at each camera move with the integrator prepared once: NEE++'s map and
    // its totals carry over and keep growing, where a render that prepares again starts them anew.
    auto scene = demo_scene(32, 18);
    RenderJob job;
    job.spp = 8;
    auto merged_passes = [](const Integrator &i) {
        return i.statistics()["shadow_rays"]["roulette"]["passes_merged"].get<uint64_t>();
    };
    auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", "neepp"}}));
    const RenderResult first = render(*scene, *integ, job);
    const uint64_t after_first = merged_passes(*integ);
    ASSERT_EQ(after_first, uint64_t(first.passes));
    scene->camera.to_world = Transform::translate(Vec3(0.05f, 0.f, 0.f)) * scene->camera.to_world;  // a move
    scene->camera.finalize();
    job.prepared = true;
    const RenderResult kept = render(*scene, *integ, job);
    EXPECT_EQ(merged_passes(*integ), after_first + uint64_t(kept.passes));
    EXPECT_EQ(kept.spp, 8);
    EXPECT_GT(pixel_statistics(kept.image, 0).mean, 0.0);
    job.prepared = false;
    const RenderResult fresh = render(*scene, *integ, job);
    EXPECT_EQ(merged_passes(*integ), uint64_t(fresh.passes));
}

TEST(RenderLoop, NeedsASampleCountOrATimeLimit) {
    auto scene = demo_scene(8, 8);
    auto integ = make_integrator("path", Options());
    RenderJob job;
    job.spp = 0;
    EXPECT_THROW(render(*scene, *integ, job), std::invalid_argument);
}

}  // namespace
