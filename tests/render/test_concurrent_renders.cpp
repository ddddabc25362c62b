// Renders at the same time in one process (issue 43), as the Python package's threads make them: two
// renders on two threads, a render while a scene loads, a render cancelled from its progress listener.
// Each gives the image it gives alone, to the bit, none imposes its thread count on another, and nothing
// hangs. scripts/test_tsan.sh runs these under ThreadSanitizer (test_render): that is where the Python
// tests' threads are checked for data races, the interpreter being uninstrumented.
#include <gtest/gtest.h>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <future>
#include <latch>
#include <thread>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// Small: under ThreadSanitizer a render is some twenty times slower.
std::unique_ptr<Scene> small_scene(const char *name) {
    return load_scene(std::string(NEEPP_SOURCE_DIR) + "/scenes/" + name + "/scene.xml", {{"resx", "20"}, {"resy", "14"}});
}

// Two renders that differ in what the library could share between them: scene, integrator (NEE++'s map
// learnt between passes; BDPT's splats), thread count.
struct Render {
    const Scene &scene;
    std::string integrator;
    OptionMap options;
    int spp, threads;
    uint64_t seed;
    RenderResult operator()(const std::function<void(RenderJob &)> &adjust = {}) const {
        auto made = make_integrator(integrator, Options(options));
        RenderJob job;
        job.spp = spp;
        job.threads = threads;
        job.seed = seed;
        if (adjust) adjust(job);
        return render(scene, *made, job);
    }
};

// Runs the jobs on threads of their own, released together; a deadlock aborts (with a message) instead of
// hanging the suite, since a thread stuck in a render cannot be stopped.
void run_at_once(const std::vector<std::function<void()>> &jobs, std::chrono::seconds timeout = std::chrono::seconds(120)) {
    std::latch start(std::ptrdiff_t(jobs.size()));
    std::vector<std::future<void>> running;
    for (const auto &job : jobs)
        running.push_back(std::async(std::launch::async, [&start, &job] {
            start.arrive_and_wait();
            job();
        }));
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (auto &f : running)
        if (f.wait_until(deadline) != std::future_status::ready) {
            std::fprintf(stderr, "run_at_once: still running after %d s: deadlock\n", int(timeout.count()));
            std::abort();
        }
    for (auto &f : running) f.get();  // a job's exception (or failed ASSERT's) here
}

class ConcurrentRenders : public ::testing::Test {
protected:
    void SetUp() override {
        door = small_scene("door-ajar");
        office = small_scene("office");
    }
    Render neepp() const { return {*door, "path", {{"shadow_rays", "neepp"}}, 4, 2, 7}; }
    Render bdpt() const { return {*office, "bdpt", {}, 2, 1, 3}; }
    std::unique_ptr<Scene> door, office;
};

TEST_F(ConcurrentRenders, TwoAtOnceGiveTheImagesOfEachAlone) {
    const Image a = neepp()().image, b = bdpt()().image;
    ASSERT_GT(pixel_statistics(a, 0).mean, 0.0);
    ASSERT_GT(pixel_statistics(b, 0).mean, 0.0);
    RenderResult ra, rb, rc;
    run_at_once({[&] { ra = neepp()(); }, [&] { rb = bdpt()(); }, [&] { rc = neepp()(); }});  // rc: the same scene twice
    EXPECT_TRUE(ra.image.data == a.data);
    EXPECT_TRUE(rb.image.data == b.data);
    EXPECT_TRUE(rc.image.data == a.data);
}

size_t worker_limit() { return tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism); }

TEST_F(ConcurrentRenders, NoneImposesItsThreadCountOnAnother) {
    // A render with one thread holds on (its progress listener waits) while one with two renders: the
    // second must still be allowed its two threads, which a process-wide tbb::global_control at the first
    // one's count took away.
    std::atomic<bool> one_running{false}, two_done{false};
    size_t limit_seen = 0;
    int arena_seen = 0;
    const auto hold = [&](RenderJob &job) {
        job.on_progress = [&](double, double) {
            one_running = true;
            for (int i = 0; i < 6000 && !two_done; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
        };
    };
    const auto watch = [&](RenderJob &job) {
        job.on_snapshot = [&](int, double, const Image &) {  // between passes, on the render's own thread
            limit_seen = worker_limit();
            arena_seen = tbb::this_task_arena::max_concurrency();
        };
    };
    const Image two_alone = neepp()().image;
    RenderResult two;
    run_at_once({[&] { bdpt()(hold); },
                 [&] {
                     while (!one_running) std::this_thread::yield();
                     two = neepp()(watch);
                     two_done = true;
                 }});
    EXPECT_GE(limit_seen, 2u);
    EXPECT_EQ(arena_seen, 2);
    EXPECT_TRUE(two.image.data == two_alone.data);

    // More threads than cores: the pool is raised for the render, and back to TBB's default after it.
    const size_t cores = size_t(tbb::info::default_concurrency());
    Render many = neepp();
    many.threads = int(cores) + 2;
    many(watch);
    EXPECT_EQ(limit_seen, cores + 2);
    EXPECT_EQ(arena_seen, int(cores) + 2);
    EXPECT_EQ(worker_limit(), cores);
}

TEST_F(ConcurrentRenders, RenderWhileScenesLoad) {
    const Image alone = neepp()().image;
    std::atomic<bool> rendering{true};
    int loads = 0;
    RenderResult r;
    run_at_once({[&] {
                     r = neepp()();
                     rendering = false;
                 },
                 [&] {
                     // Parsing, meshes, the Embree BVH build (on the thread pool) while the render runs.
                     while (loads < 2 || rendering) {
                         for (const char *name : {"office", "courtyard"}) EXPECT_GT(small_scene(name)->triangle_count(), 0u);
                         loads += 2;
                     }
                 }});
    EXPECT_TRUE(r.image.data == alone.data);
    EXPECT_GE(loads, 2);
}

TEST_F(ConcurrentRenders, CancelFromTheProgressListenerLeavesTheOtherRenderAlone) {
    // As neepp.render's callback returning False: the listener sets the job's cancel flag.
    const Image alone = bdpt()().image;
    std::atomic<bool> cancel{false};
    std::atomic<int> calls{0};
    RenderResult cancelled, other;
    const auto start = std::chrono::steady_clock::now();
    run_at_once({[&] {
                     cancelled = neepp()([&](RenderJob &job) {
                         job.spp = 0;
                         job.time_limit_s = 60;
                         job.cancel = &cancel;
                         job.on_progress = [&](double, double) {
                             if (++calls == 2) cancel = true;
                         };
                     });
                 },
                 [&] { other = bdpt()(); }});
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
    EXPECT_EQ(cancelled.stopped_by, "cancel");
    EXPECT_EQ(cancelled.image.width, 20);
    EXPECT_GE(calls.load(), 2);
    EXPECT_TRUE(other.image.data == alone.data);
}

}  // namespace
