// The render loop: sample counts, time limits and cancellation, always ending with an image.
#include <gtest/gtest.h>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>
#include "neepp/sampling/sampler.h"
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

// A slow integrator whose samples are random colours of their own sampler: a pass of it takes long enough
// for the display to show it under way, and each pixel's value says which samples are in it.
class SlowIntegrator final : public RayIntegrator {
public:
    explicit SlowIntegrator(std::chrono::microseconds per_sample) : per_sample_(per_sample) {}
    Color Li(const Scene &, const Ray &, Sampler &sampler, RenderCounters &counters) const override {
        std::this_thread::sleep_for(per_sample_);
        ++counters.rays;
        const float r = sampler.next_1d(), g = sampler.next_1d();
        return Color(r, g, sampler.next_1d());
    }
    nlohmann::json describe() const override { return {{"name", "slow"}}; }

private:
    std::chrono::microseconds per_sample_;
};

// What a render showed: every frame, in order, and from which threads.
struct Shown {
    std::mutex mutex;
    std::vector<DisplayFrame> frames;
    void operator()(DisplayFrame f) {
        std::lock_guard<std::mutex> lock(mutex);
        frames.push_back(std::move(f));
    }
};

TEST(RenderLoop, ShowsAPassUnderWayAsTheCompletedPassesAndWholeFinishedTiles) {
    // A box filter: a pixel's value is its own samples' mean, so each pixel of a frame within the second
    // pass is either the first pass's image or the second's, to the bit, and a tile is all one or the other.
    auto scene = demo_scene(64, 32);
    scene->settings.rfilter = "box";
    scene->settings.rfilter_radius = 0.5f;
    SlowIntegrator integ(std::chrono::microseconds(100));
    RenderJob job;
    job.tile_size = 8;
    job.threads = 2;
    job.spp = 1;
    const Image first = render(*scene, integ, job).image;  // the first pass alone
    job.spp = 3;                                           // passes of 1 and 2 spp
    const RenderResult plain = render(*scene, integ, job);
    ASSERT_EQ(plain.passes, 2);

    Shown shown;
    job.on_display = std::ref(shown);
    job.display_within_pass = true;
    job.display_interval_s = 0.005;
    const RenderResult r = render(*scene, integ, job);
    EXPECT_TRUE(r.image.data == plain.image.data);  // the frames only read
    ASSERT_FALSE(shown.frames.empty());
    EXPECT_TRUE(shown.frames.back().final);
    EXPECT_TRUE(shown.frames.back().image.data == r.image.data);

    const int W = 64, H = 32, T = 8;
    int within = 0, partial = 0;
    double last_mean = 0;
    for (const DisplayFrame &f : shown.frames) {
        EXPECT_GE(f.spp_mean, last_mean);  // never an older image after a newer one
        last_mean = f.spp_mean;
        if (!f.within_pass) {
            EXPECT_EQ(f.spp_max, f.spp);
            EXPECT_EQ(f.spp_mean, double(f.spp));
            continue;
        }
        ++within;
        EXPECT_FALSE(f.final);
        EXPECT_EQ(f.spp, 1);  // none before the first pass is complete
        ASSERT_EQ(f.image.width, W);
        int tiles_ahead = 0;
        for (int ty = 0; ty < H; ty += T)
            for (int tx = 0; tx < W; tx += T) {
                int as_first = 0, as_final = 0;
                for (int y = ty; y < ty + T; ++y)
                    for (int x = tx; x < tx + T; ++x)
                        for (int c = 0; c < 3; ++c) {
                            const size_t i = (size_t(y) * W + x) * 3 + c;
                            as_first += f.image.data[i] == first.data[i];
                            as_final += f.image.data[i] == plain.image.data[i];
                        }
                // A tile is all in or all out: never torn.
                EXPECT_TRUE(as_first == T * T * 3 || as_final == T * T * 3) << "tile " << tx << "," << ty;
                tiles_ahead += as_final == T * T * 3;
            }
        EXPECT_EQ(f.spp_max, tiles_ahead > 0 ? 3 : 1);
        EXPECT_DOUBLE_EQ(f.spp_mean, 1 + 2 * double(tiles_ahead) / ((W / T) * (H / T)));
        partial += tiles_ahead > 0 && tiles_ahead < (W / T) * (H / T);
        EXPECT_EQ(f.counters.rays, uint64_t(W) * H);  // the completed pass's
    }
    // The second pass takes about 2048 samples x 100 us / 2 threads: frames every 5 ms show it under way.
    EXPECT_GE(within, 3);
    EXPECT_GE(partial, 2);
}

TEST(RenderLoop, ShowsTheFirstPassUnderWayAsItsFinishedTilesAndMarksTheRest) {
    // RenderJob::display_first_pass: within the first pass, the pixels of its finished tiles are the pass's
    // image to the bit (a box filter: a pixel is its own samples' mean) and every other pixel is NaN, whole
    // tiles at a time; spp says no pixel has a sample for sure. The image and its sums stay a plain render's.
    auto scene = demo_scene(64, 32);
    scene->settings.rfilter = "box";
    scene->settings.rfilter_radius = 0.5f;
    SlowIntegrator integ(std::chrono::microseconds(100));
    RenderJob job;
    job.tile_size = 8;
    job.threads = 2;
    job.spp = 1;
    job.keep_state = true;
    const RenderResult plain = render(*scene, integ, job);  // the first pass alone

    Shown shown;
    job.on_display = std::ref(shown);
    job.display_within_pass = true;
    job.display_first_pass = true;
    job.display_interval_s = 0.005;
    const RenderResult r = render(*scene, integ, job);
    EXPECT_TRUE(r.image.data == plain.image.data);
    EXPECT_TRUE(r.state.image_sums == plain.state.image_sums);

    const int W = 64, H = 32, T = 8, tiles = (W / T) * (H / T);
    int within = 0, partial = 0;
    for (const DisplayFrame &f : shown.frames) {
        if (!f.within_pass) continue;
        ++within;
        EXPECT_EQ(f.spp, 0);
        int finished = 0;
        for (int ty = 0; ty < H; ty += T)
            for (int tx = 0; tx < W; tx += T) {
                int exact = 0, marked = 0;
                for (int y = ty; y < ty + T; ++y)
                    for (int x = tx; x < tx + T; ++x)
                        for (int c = 0; c < 3; ++c) {
                            const size_t i = (size_t(y) * W + x) * 3 + c;
                            exact += f.image.data[i] == plain.image.data[i];
                            marked += std::isnan(f.image.data[i]);
                        }
                EXPECT_TRUE(exact == T * T * 3 || marked == T * T * 3) << "tile " << tx << "," << ty;
                finished += exact == T * T * 3;
            }
        EXPECT_GT(finished, 0);  // a frame comes once a tile is finished, not before
        EXPECT_EQ(f.spp_max, 1);
        EXPECT_DOUBLE_EQ(f.spp_mean, double(finished) / tiles);
        partial += finished < tiles;
    }
    // The pass takes about 2048 samples x 100 us / 2 threads: frames every 5 ms show it under way.
    EXPECT_GE(within, 3);
    EXPECT_GE(partial, 2);

    // Without display_first_pass nothing is shown before the first pass is complete; nor for a splatting
    // integrator, whose first pass's splats are known only at its end.
    Shown without;
    job.on_display = std::ref(without);
    job.display_first_pass = false;
    render(*scene, integ, job);
    for (const DisplayFrame &f : without.frames) EXPECT_FALSE(f.within_pass);
    auto light = make_integrator("light", Options(OptionMap{{"shadow_rays", "nee"}}));
    Shown splatted;
    job.on_display = std::ref(splatted);
    job.display_first_pass = true;
    job.display_interval_s = 0;
    job.spp = 2;
    render(*scene, *light, job);
    for (const DisplayFrame &f : splatted.frames) {
        EXPECT_GE(f.spp, 1);
        for (float v : f.image.data) ASSERT_FALSE(std::isnan(v));
    }
}

TEST(RenderLoop, FramesWithinAPassAreTheIntervalApartFromStartToStart) {
    // What a frame within a pass takes (on_display here sleeps 60 ms; on a loaded machine, the wait for a
    // core) does not add to the display interval: frames 50 ms apart come every 60 ms, where counting the
    // interval from the end of the last frame made it 110 ms.
    auto scene = demo_scene(64, 32);
    SlowIntegrator integ(std::chrono::microseconds(100));
    RenderJob job;
    job.tile_size = 8;
    job.threads = 2;
    job.spp = 5;  // passes of 1 and 4 spp: about 0.1 s and 0.4 s
    std::vector<double> starts;
    job.on_display = [&](DisplayFrame f) {
        if (!f.within_pass) return;  // (a slow frame between passes is the render's time: shown less often)
        starts.push_back(f.render_time_s);
        std::this_thread::sleep_for(std::chrono::milliseconds(60));
    };
    job.display_within_pass = true;
    job.display_interval_s = 0.05;
    render(*scene, integ, job);
    ASSERT_GE(starts.size(), 4u);
    std::vector<double> gaps;
    for (size_t i = 1; i < starts.size(); ++i) gaps.push_back(starts[i] - starts[i - 1]);
    std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
    EXPECT_LT(gaps[gaps.size() / 2], 0.09);
}

TEST(RenderLoop, FramesWithinAPassLeaveTheImageAndItsSumsAsTheyAre) {
    // Path tracing (a tent filter: tiles' blocks overlap) and the splatting integrators, shown as often
    // as the display thread can: the image and the sums are a render's without a display, to the bit. Path
    // tracing on two threads (tiles added in tile order whichever finishes first); the splatting ones on
    // one, as their splats land in the pass's film in the order the threads put them.
    auto scene = demo_scene(64, 36);
    for (const char *name : {"path", "bdpt", "light"}) {
        SCOPED_TRACE(name);
        auto integ = make_integrator(name, Options(OptionMap{{"shadow_rays", "nee"}}));
        RenderJob job;
        job.spp = 16;
        job.tile_size = 8;
        job.threads = std::string(name) == "path" ? 2 : 1;
        job.keep_state = true;
        const RenderResult plain = render(*scene, *integ, job);
        Shown shown;
        job.on_display = std::ref(shown);
        job.display_within_pass = true;
        job.display_interval_s = 0;
        const RenderResult r = render(*scene, *integ, job);
        EXPECT_TRUE(r.image.data == plain.image.data);
        EXPECT_TRUE(r.state.image_sums == plain.state.image_sums);
        EXPECT_TRUE(r.state.splat_sums == plain.state.splat_sums);
        int within = 0;
        for (const DisplayFrame &f : shown.frames) {
            within += f.within_pass;
            EXPECT_GE(f.spp, 1);
            EXPECT_LE(f.spp_max, 16);
            for (float v : f.image.data) ASSERT_TRUE(std::isfinite(v));
        }
        EXPECT_GT(within, 0);  // the frames were shown within a pass
    }
}

TEST(RenderLoop, ThreadsRenderTheSameImageEachTime) {
    // A tent filter and small tiles: most pixels take samples from several tiles' blocks, which four
    // threads on however many cores finish in an order of their own each time (before tiles were added
    // in tile order, about one render in two here differed in some pixels' last bits).
    auto scene = demo_scene(64, 36);
    auto integ = make_integrator("path", Options(OptionMap{{"shadow_rays", "nee"}}));
    RenderJob job;
    job.spp = 8;
    job.tile_size = 4;
    job.threads = 4;
    job.keep_state = true;
    const RenderResult a = render(*scene, *integ, job);
    for (int run = 0; run < 4; ++run) {
        const RenderResult b = render(*scene, *integ, job);
        ASSERT_TRUE(b.image.data == a.image.data) << "run " << run;
        ASSERT_TRUE(b.state.image_sums == a.state.image_sums) << "run " << run;
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
