// Checkpoints: a render stopped at a pass boundary and resumed from its checkpoint reaches the same
// sums, to the bit, as one that never stopped; checkpoint files round-trip and refuse damage.
#include <gtest/gtest.h>
#include <atomic>
#include <chrono>
#include <fstream>
#include <thread>
#include <vector>
#include "common/temp_dir.h"
#include "neepp/render/checkpoint.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

std::unique_ptr<Scene> project_scene(const std::string &name) {
    return load_scene(std::string(NEEPP_SOURCE_DIR) + "/scenes/" + name + "/scene.xml", {{"resx", "40"}, {"resy", "24"}});
}

// Renders to spp in one go, then to `first` spp with a checkpoint after every pass, then resumes each
// checkpoint to spp: every resumed image must be identical to the uninterrupted one.
void expect_resume_is_exact(const std::string &integrator_name, const OptionMap &o, int first, int spp,
                            const std::string &scene_name = "door-ajar") {
    auto scene = project_scene(scene_name);
    Options options(scene->settings.integrator_options);
    for (const auto &[k, v] : o) options.set(k, v);
    RenderJob job;
    job.spp = spp;
    job.seed = 7;
    auto whole = make_integrator(integrator_name, options);
    const RenderResult reference = render(*scene, *whole, job);

    std::vector<RenderCheckpoint> saved;
    RenderJob part = job;
    part.spp = first;
    part.checkpoint_interval_s = 1e-9;  // after every pass
    part.on_checkpoint = [&](const RenderCheckpoint &c, const Image &) { saved.push_back(c); };
    auto first_integrator = make_integrator(integrator_name, options);
    render(*scene, *first_integrator, part);
    ASSERT_FALSE(saved.empty());  // after each pass but the last (which reached the sample count)
    EXPECT_EQ(saved.front().spp, 1);

    // Resume from every checkpoint the first render took, each in a fresh integrator.
    for (const RenderCheckpoint &c : saved) {
        SCOPED_TRACE(c.spp);
        RenderJob resume = job;
        resume.resume = &c;
        auto resumed_integrator = make_integrator(integrator_name, options);
        const RenderResult resumed = render(*scene, *resumed_integrator, resume);
        EXPECT_EQ(resumed.spp, spp);
        EXPECT_EQ(resumed.resumed_spp, c.spp);
        EXPECT_EQ(resumed.image.data, reference.image.data);
        EXPECT_EQ(resumed.counters.rays, reference.counters.rays);
        EXPECT_EQ(resumed.counters.splats, reference.counters.splats);
    }
}

TEST(Checkpoint, PathResumesToTheSameImage) { expect_resume_is_exact("path", {{"shadow_rays", "nee"}}, 40, 70); }

TEST(Checkpoint, BdptResumesToTheSameImageSplatsIncluded) { expect_resume_is_exact("bdpt", {}, 5, 9); }

TEST(Checkpoint, LightTracingResumesToTheSameImage) { expect_resume_is_exact("light", {}, 5, 9); }

// NEE++ learns between passes: the map, the first pass's decision to reject or not, the adaptive
// policy's calibration. A resumed render must read in each pass what the uninterrupted one read.
TEST(Checkpoint, NeeppResumesToTheSameImage) {
    expect_resume_is_exact("path", {{"shadow_rays", "neepp"}}, 12, 20);
    expect_resume_is_exact("path", {{"shadow_rays", "neepp-adaptive"}}, 12, 20);
}

// Guiding learns from every pass: a resumed render samples the guide the uninterrupted one did.
TEST(Checkpoint, GuidedPathResumesToTheSameImage) {
    expect_resume_is_exact("path", {{"guiding", "sdtree"}}, 6, 10);
    expect_resume_is_exact("path", {{"guiding", "sdtree"}, {"shadow_rays", "neepp"}}, 6, 10);
    expect_resume_is_exact("path", {{"guiding", "map"}}, 6, 10);
    expect_resume_is_exact("path", {{"guiding", "sdtree+map"}}, 6, 10);
}

TEST(Checkpoint, VisibilityAwareLightSelectionResumesToTheSameImage) {
    expect_resume_is_exact("path", {{"light_sampler", "visibility"}, {"shadow_rays", "neepp-adaptive"}}, 12, 20, "office");
}

TEST(Checkpoint, BdptWithNeeppSelectionResumesToTheSameImage) {
    expect_resume_is_exact("bdpt", {{"light_paths", "neepp"}}, 6, 9);
}

// PSSMLT's chains are its state: they resume where the last complete pass left them. With NEE++ the
// map too, which the chains' states are evaluated again under.
TEST(Checkpoint, PssmltResumesToTheSameImage) {
    expect_resume_is_exact("pssmlt", {{"chains", "16"}, {"bootstrap", "2000"}}, 6, 9);
    expect_resume_is_exact("pssmlt", {{"chains", "16"}, {"bootstrap", "2000"}, {"shadow_rays", "neepp"}}, 6, 9);
}

// A pass cut short (Ctrl-C) has moved the chains on: its checkpoint holds them as the pass found them.
TEST(Checkpoint, PssmltPassCutShortIsNotInItsCheckpoint) {
    auto scene = project_scene("door-ajar");
    Options options(scene->settings.integrator_options);
    options.set("chains", "16");
    options.set("bootstrap", "2000");
    RenderJob job;
    job.spp = 1000;  // never reached: cancelled first
    job.seed = 3;
    job.threads = 1;
    std::vector<RenderCheckpoint> saved;
    std::atomic<bool> cancel{false};
    RenderJob part = job;
    part.checkpoint_interval_s = 1e-9;
    part.cancel = &cancel;
    // Cancelled from inside a pass after the fourth: a chain checks between its mutations.
    std::thread canceller;
    part.on_checkpoint = [&](const RenderCheckpoint &c, const Image &) {
        saved.push_back(c);
        if (saved.size() == 4)
            canceller = std::thread([&] { std::this_thread::sleep_for(std::chrono::milliseconds(30)); cancel = true; });
    };
    auto first = make_integrator("pssmlt", options);
    const RenderResult stopped = render(*scene, *first, part);
    canceller.join();
    ASSERT_EQ(stopped.stopped_by, "cancel");
    ASSERT_GE(saved.size(), 5u);
    const RenderCheckpoint &last = saved.back();  // taken at the stop, of the passes completed
    RenderJob whole = job;
    whole.spp = last.spp + 8;
    auto reference = make_integrator("pssmlt", options);
    const RenderResult ref = render(*scene, *reference, whole);
    RenderJob resume = whole;
    resume.resume = &last;
    auto resumed = make_integrator("pssmlt", options);
    const RenderResult r = render(*scene, *resumed, resume);
    EXPECT_EQ(r.image.data, ref.image.data) << "resumed from " << last.spp << " spp";
    EXPECT_EQ(r.counters.rays, ref.counters.rays);
}

TEST(Checkpoint, FilesRoundTripAndRefuseDamage) {
    TempDir tmp;
    RenderCheckpoint c;
    c.identity = R"({"seed":3})";
    c.spp = 33;
    c.passes = 2;
    c.render_time_s = 1.5;
    c.seconds_per_spp = 0.01;
    c.light_paths = 1234;
    c.counters.rays = 99;
    c.counters.splats = 7;
    c.image_sums = {1.0, 2.0, 3.0, 0.25, -1e-300, 5, 6, 7};
    c.splat_sums = {int64_t(1) << 40, -3, 0};
    const std::string path = (tmp.dir / "a.checkpoint").string();
    save_checkpoint(path, c);
    const RenderCheckpoint back = load_checkpoint(path);
    EXPECT_EQ(back.identity, c.identity);
    EXPECT_EQ(back.spp, 33);
    EXPECT_EQ(back.passes, 2);
    EXPECT_EQ(back.render_time_s, 1.5);
    EXPECT_EQ(back.light_paths, 1234);
    EXPECT_EQ(back.counters.rays, 99u);
    EXPECT_EQ(back.counters.splats, 7u);
    EXPECT_EQ(back.image_sums, c.image_sums);
    EXPECT_EQ(back.splat_sums, c.splat_sums);

    std::string bytes;
    {
        std::ifstream in(path, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    for (size_t at : {size_t(9), bytes.size() / 2, bytes.size() - 1}) {
        std::string damaged = bytes;
        damaged[at] ^= 0x10;
        EXPECT_THROW(load_checkpoint(tmp.write("d.checkpoint", damaged)), std::runtime_error) << at;
    }
    EXPECT_THROW(load_checkpoint(tmp.write("t.checkpoint", bytes.substr(0, bytes.size() / 2))), std::runtime_error);
    EXPECT_THROW(load_checkpoint(tmp.write("v.checkpoint", "a visibility map, say")), std::runtime_error);
    EXPECT_THROW(load_checkpoint((tmp.dir / "none").string()), std::runtime_error);
}

}  // namespace
