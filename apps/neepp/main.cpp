// The `neepp` command-line tool: render a Mitsuba 3 scene, or the built-in demo.
#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include "neepp/integrators/integrator.h"
#include "neepp/loader/scene_loader.h"
#include "neepp/render/render_output.h"

#ifndef NEEPP_SCENES_DIR
#define NEEPP_SCENES_DIR "scenes"
#endif

namespace {

std::atomic<bool> g_cancel{false};

extern "C" void on_sigint(int) {
    // First Ctrl-C: stop after the current tile and write what we have. Second: the default action.
    g_cancel = true;
    std::signal(SIGINT, SIG_DFL);
}

std::pair<std::string, std::string> split_key_value(const std::string &s, const char *what) {
    auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw CLI::ValidationError(std::string(what) + " expects name=value, got '" + s + "'");
    return {s.substr(0, eq), s.substr(eq + 1)};
}

struct RenderArgs {
    std::string scene, output = "render.exr", integrator, stats, sampler, rfilter;
    int spp = 0, threads = 0;
    double time_s = 0;
    uint64_t seed = 0;
    std::vector<std::string> defines, integrator_options;
    bool quiet = false;
};

// Loads, renders and writes one image; returns the statistics.
nlohmann::json run_render(const RenderArgs &a) {
    std::map<std::string, std::string> defines;
    for (auto &d : a.defines) defines.insert(split_key_value(d, "-D"));
    if (a.spp > 0 && !defines.count("spp")) defines["spp"] = std::to_string(a.spp);
    auto scene = neepp::load_scene(a.scene, defines);
    if (!a.rfilter.empty()) {  // e.g. box, so a low-resolution render matches a box-downsampled reference
        scene->settings.rfilter = a.rfilter;
        scene->settings.rfilter_radius = a.rfilter == "box" ? 0.5f : a.rfilter == "tent" ? 1.f : 4.f * scene->settings.rfilter_stddev;
    }

    neepp::Options options(scene->settings.integrator_options);
    for (auto &o : a.integrator_options) {
        auto [k, v] = split_key_value(o, "-I");
        options.set(k, v);
    }
    std::string name = a.integrator.empty() ? scene->settings.integrator : a.integrator;
    auto integrator = neepp::make_integrator(name, options);

    neepp::RenderJob job;
    job.spp = a.spp > 0 ? a.spp : (a.time_s > 0 ? 0 : scene->settings.spp);
    job.time_limit_s = a.time_s;
    job.seed = a.seed;
    job.threads = a.threads;
    job.sampler = a.sampler.empty() ? scene->settings.sampler : a.sampler;
    job.progress = !a.quiet && isatty(STDERR_FILENO);
    job.cancel = &g_cancel;
    if (!a.quiet)
        fmt::print(stderr, "neepp: {} ({}x{}, {} triangles, {} lights), integrator {}, {}\n", a.scene,
                   scene->camera.width, scene->camera.height, scene->triangle_count(), scene->lights().size(), name,
                   job.spp > 0 ? fmt::format("{} spp", job.spp) : fmt::format("{} s", job.time_limit_s));

    neepp::RenderResult result = neepp::render(*scene, *integrator, job);
    std::string png = neepp::write_render_images(a.output, result.image);
    nlohmann::json stats = neepp::render_statistics(*scene, *integrator, result, job);
    if (!a.stats.empty()) std::ofstream(a.stats) << stats.dump(2) << "\n";
    if (!a.quiet)
        fmt::print(stderr, "neepp: {} spp in {:.2f} s ({:.3f} M samples/s, stopped by {}), wrote {} and {}\n", result.spp,
                   result.render_time_s, stats["samples_per_s"].get<double>() * 1e-6, result.stopped_by, a.output, png);
    return stats;
}

}  // namespace

int main(int argc, char **argv) {
    CLI::App app{"neepp: a physically based renderer with Next Event Estimation++"};
    app.require_subcommand(1);

    RenderArgs ra;
    auto *render = app.add_subcommand("render", "Render a Mitsuba 3 XML scene");
    render->add_option("scene", ra.scene, "Scene file (Mitsuba 3 XML)")->required()->check(CLI::ExistingFile);
    render->add_option("-o,--output", ra.output, "Output EXR (a PNG is written beside it)");
    auto *spp = render->add_option("--spp", ra.spp, "Samples per pixel (default: the scene's)")->check(CLI::Range(1, 1 << 24));
    render->add_option("--time", ra.time_s, "Render for this many seconds instead")->check(CLI::PositiveNumber)->excludes(spp);
    render->add_option("--seed", ra.seed, "Random seed");
    render->add_option("--threads", ra.threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
    render->add_option("-D", ra.defines, "Scene parameter override name=value (as mitsuba -D)");
    render->add_option("--integrator", ra.integrator, "Integrator (default: the scene's)");
    render->add_option("-I", ra.integrator_options, "Integrator option key=value");
    render->add_option("--sampler", ra.sampler, "Sampler: independent or sobol (default: the scene's)");
    render->add_option("--rfilter", ra.rfilter, "Override the film's reconstruction filter")
        ->check(CLI::IsMember({"box", "tent", "gaussian"}));
    render->add_option("--stats", ra.stats, "Write statistics JSON here");
    render->add_flag("-q,--quiet", ra.quiet, "No progress bar or messages");

    std::string demo_dir = "neepp-demo";
    int demo_spp = 64;
    bool demo_quiet = false;
    auto *demo = app.add_subcommand("demo", "Render the built-in demo scene (a room lit through a door ajar)");
    demo->add_option("-o,--output-dir", demo_dir, "Directory for the demo's images and statistics");
    demo->add_option("--spp", demo_spp, "Samples per pixel")->check(CLI::Range(1, 1 << 20));
    demo->add_flag("-q,--quiet", demo_quiet, "No progress bar or messages");

    CLI11_PARSE(app, argc, argv);
    std::signal(SIGINT, on_sigint);
    try {
        if (*render) {
            run_render(ra);
        } else if (*demo) {
            std::filesystem::create_directories(demo_dir);
            RenderArgs d;
            d.scene = std::string(NEEPP_SCENES_DIR) + "/door-ajar/scene.xml";
            d.output = demo_dir + "/demo_nee.exr";
            d.stats = demo_dir + "/demo_nee.json";
            d.spp = demo_spp;
            d.quiet = demo_quiet;
            run_render(d);
        }
    } catch (const std::exception &e) {
        fmt::print(stderr, "neepp: error: {}\n", e.what());
        return 1;
    }
    return g_cancel ? 130 : 0;
}
