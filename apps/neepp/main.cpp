// The `neepp` command-line tool: render a Mitsuba 3 scene, or the built-in demo.
#include <atomic>
#include <chrono>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include "neepp/display/tev_display.h"
#include "neepp/integrators/factory.h"
#include "neepp/integrators/option_table.h"
#include "neepp/io/atomic_file.h"
#include "neepp/light_selection/factory.h"
#include "neepp/loader/scene_loader.h"
#include "neepp/loader/supported_plugins.h"
#include "neepp/render/checkpoint_identity.h"
#include "neepp/render/huge_pages.h"
#include "neepp/render/render_output.h"
#include "neepp/visibility/map_file.h"

#ifndef NEEPP_SCENES_DIR
#define NEEPP_SCENES_DIR "scenes"
#endif
#ifndef NEEPP_VERSION
#define NEEPP_VERSION "unknown"
#endif

namespace {

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};

extern "C" void on_stop_signal(int sig) {
    // First Ctrl-C or SIGTERM (a batch system's stop, `kill`): stop after the current tile and write what
    // we have. A second: the default action.
    g_signal = sig;
    g_cancel = true;
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
}

std::pair<std::string, std::string> split_key_value(const std::string &s, const char *what) {
    auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw CLI::ValidationError(std::string(what) + " expects name=value, got '" + s + "'");
    return {s.substr(0, eq), s.substr(eq + 1)};
}

struct RenderArgs {
    std::string scene, output = "render.exr", integrator, stats, sampler, rfilter, visibility_map, snapshots;
    std::string display_server;  // HOST:PORT of a tev to show the render in as it converges
    int spp = 0, threads = 0;
    double time_s = 0, checkpoint_s = 0;
    bool resume = false;
    std::optional<uint64_t> seed;  // default: the scene's sampler seed
    std::string png = "auto";      // auto: a PNG beside the EXR; none
    std::vector<int> crop;         // x, y, w, h: render only this window of the film
    std::vector<std::string> defines, integrator_options;
    bool quiet = false;
};

// Checks before a render that its files can be written, so that a typing slip costs no render: the
// folders are created (as `-o out/a.exr` asks), and a folder that cannot be made or written, or an image
// name that is not .exr (the PNG beside it takes the same name with .png, so `-o a.png` would leave
// only a PNG), is an error before the scene is even loaded.
void check_output_path(const std::string &path, const char *what, const char *extension) {
    namespace fs = std::filesystem;
    const fs::path file(path);
    if (extension && file.extension() != extension)
        throw std::runtime_error(fmt::format("the {} '{}' must end in {}", what, path, extension));
    if (fs::is_directory(file)) throw std::runtime_error(fmt::format("the {} '{}' is a folder", what, path));
    const fs::path dir = file.parent_path().empty() ? fs::path(".") : file.parent_path();
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir))
        throw std::runtime_error(fmt::format("cannot create the folder '{}' for the {} '{}': {}", dir.string(), what,
                                             path, ec ? ec.message() : "a file of that name exists"));
    if (access(dir.c_str(), W_OK) != 0)
        throw std::runtime_error(fmt::format("cannot write the {} '{}': the folder '{}' is not writable", what, path,
                                             dir.string()));
}

struct Rendered {
    neepp::Image image;
    nlohmann::json stats;
};

// The EXR, and the PNG beside it unless --png none; returns what was written, for messages.
std::string write_images(const RenderArgs &a, const neepp::Image &image) {
    if (a.png == "none") {
        neepp::write_exr(a.output, image);
        return "no PNG (--png none)";
    }
    return neepp::write_render_images(a.output, image);
}

// Loads, renders and writes one image; returns it with its statistics.
Rendered run_render(const RenderArgs &a) {
    check_output_path(a.output, "output image", ".exr");
    if (!a.stats.empty()) check_output_path(a.stats, "statistics file", nullptr);
    if (!a.visibility_map.empty()) check_output_path(a.visibility_map, "visibility map", nullptr);
    std::map<std::string, std::string> defines;
    for (auto &d : a.defines) defines.insert(split_key_value(d, "-D"));
    // --spp also fills a scene's $spp (and sets the count itself below, so a scene without one still gets it).
    std::set<std::string> own;
    if (a.spp > 0 && !defines.count("spp")) {
        defines["spp"] = std::to_string(a.spp);
        own.insert("spp");
    }
    // Loading (parsing, meshes, textures, the BVH) is timed apart from rendering, as Mitsuba's load is.
    const auto load_start = std::chrono::steady_clock::now();
    auto scene = neepp::load_scene(a.scene, defines, own);
    const double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
    if (!a.rfilter.empty()) {  // e.g. box, so a low-resolution render matches a box-downsampled reference
        scene->settings.rfilter = a.rfilter;
        scene->settings.rfilter_radius = a.rfilter == "box" ? 0.5f : a.rfilter == "tent" ? 1.f : 4.f * scene->settings.rfilter_stddev;
    }

    if (!a.crop.empty()) {
        if (a.crop.size() != 4) throw std::runtime_error("--crop expects x,y,w,h");
        try {
            scene->camera.crop(a.crop[0], a.crop[1], a.crop[2], a.crop[3]);
            scene->camera.finalize();
        } catch (const std::invalid_argument &e) {
            throw std::runtime_error(std::string("--crop: ") + e.what());
        }
    }
    neepp::Options options(scene->settings.integrator_options);
    if (!a.visibility_map.empty()) options.set("visibility_map", a.visibility_map);
    for (auto &o : a.integrator_options) {
        auto [k, v] = split_key_value(o, "-I");
        options.set(k, v);
    }
    std::string name = a.integrator.empty() ? scene->settings.integrator : a.integrator;
    auto integrator = neepp::make_integrator(name, options);

    neepp::RenderJob job;
    job.spp = a.spp > 0 ? a.spp : (a.time_s > 0 ? 0 : scene->settings.spp);
    job.time_limit_s = a.time_s;
    job.seed = a.seed.value_or(scene->settings.seed);
    job.threads = a.threads;
    job.sampler = a.sampler.empty() ? scene->settings.sampler : a.sampler;
    // A redrawn bar on a terminal; elsewhere (a log file, a batch system) a line per tenth of the render.
    job.progress = a.quiet ? neepp::ProgressStyle::none
                           : isatty(STDERR_FILENO) ? neepp::ProgressStyle::bar : neepp::ProgressStyle::log;
    job.cancel = &g_cancel;
    // --checkpoint writes the render's state beside the image (OUTPUT.checkpoint) and the image so far;
    // --resume continues from that state. A render that reaches its sample count removes it.
    const std::string checkpoint_path = a.output + ".checkpoint";
    const nlohmann::json identity = neepp::render_identity(*scene, *integrator, job.seed, job.sampler, defines);
    neepp::RenderCheckpoint resumed;
    if (a.resume) {
        resumed = neepp::checkpoint_to_resume(checkpoint_path, identity);
        job.resume = &resumed;
    }
    if (a.checkpoint_s > 0) {
        job.checkpoint_interval_s = a.checkpoint_s;
        job.on_checkpoint = [&](const neepp::RenderCheckpoint &c, const neepp::Image &image) {
            neepp::RenderCheckpoint with_identity = c;
            with_identity.identity = identity.dump();
            neepp::save_checkpoint(checkpoint_path, with_identity);
            write_images(a, image);
        };
    }
    // --snapshots DIR: the image at geometrically spaced times, for convergence plots (neepp compare).
    nlohmann::json snapshot_index = nlohmann::json::array();
    auto write_snapshot = [&](int spp, double time_s, const neepp::Image &image) {
        const std::string file = fmt::format("snapshot_{:03d}.exr", snapshot_index.size());
        neepp::write_exr(a.snapshots + "/" + file, image);
        snapshot_index.push_back({{"file", file}, {"spp", spp}, {"render_time_s", time_s}});
        neepp::write_file_atomically(a.snapshots + "/snapshots.json", snapshot_index.dump(1) + "\n");
    };
    if (!a.snapshots.empty()) {
        check_output_path(a.snapshots + "/snapshots.json", "snapshot folder", nullptr);
        job.on_snapshot = write_snapshot;
    }
    if (!a.quiet)
        fmt::print(stderr, "neepp: {} ({}x{}, {} triangles, {} lights, loaded in {:.2f} s), integrator {}, {}\n",
                   a.scene, scene->camera.width, scene->camera.height, scene->triangle_count(), scene->lights().size(),
                   load_s, name,
                   job.spp > 0 ? fmt::format("{} spp", job.spp) : fmt::format("{} s", job.time_limit_s));

    // --display-server: the image a few times a second (after a pass, or within a long one the tiles it
    // finished, once a first pass is complete) and the final one, sent by a thread of the display's own;
    // the image is named as the output file, so a render of the same file again replaces it in tev.
    std::unique_ptr<neepp::TevDisplay> display;
    if (!a.display_server.empty()) {
        display = std::make_unique<neepp::TevDisplay>(neepp::parse_server_address(a.display_server), a.output,
                                                      [](const std::string &w) { fmt::print(stderr, "neepp: warning: {}\n", w); });
        job.on_display = [&](neepp::DisplayFrame frame) { display->show(std::move(frame.image)); };
        job.display_within_pass = true;
    }

    neepp::RenderResult result = neepp::render(*scene, *integrator, job);
    const std::string png = write_images(a, result.image);
    // The last snapshot is the final image (unless the last pass just took it).
    if (!a.snapshots.empty() && result.spp > 0 &&
        (snapshot_index.empty() || snapshot_index.back()["spp"].get<int>() != result.spp))
        write_snapshot(result.spp, result.render_time_s, result.image);
    if ((a.resume || a.checkpoint_s > 0) && result.stopped_by == "spp") neepp::remove_checkpoint(checkpoint_path);
    nlohmann::json stats = neepp::render_statistics(*scene, *integrator, result, job);
    stats["load_time_s"] = load_s;
    if (!a.stats.empty()) neepp::write_file_atomically(a.stats, stats.dump(2) + "\n");
    // Every file first, then at most a few seconds for a slow viewer to take the final image.
    if (display) display->finish(10.0);
    if (!a.quiet)
        fmt::print(stderr, "neepp: {} spp in {:.2f} s ({:.3f} M samples/s, stopped by {}), wrote {} and {}\n", result.spp,
                   result.render_time_s, stats["samples_per_s"].get<double>() * 1e-6, result.stopped_by, a.output, png);
    return {std::move(result.image), std::move(stats)};
}

// The two images next to each other with a thin black gap, for a person to compare at a glance.
neepp::Image side_by_side(const neepp::Image &left, const neepp::Image &right) {
    const int gap = 8;
    neepp::Image out(left.width + gap + right.width, std::max(left.height, right.height), 3);
    auto blit = [&](const neepp::Image &img, int x0) {
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x)
                for (int c = 0; c < 3; ++c) out.at(x0 + x, y, c) = img.at(x, y, std::min(c, img.channels - 1));
    };
    blit(left, 0);
    blit(right, left.width + gap);
    return out;
}

// `neepp check`: every problem, one a line as compilers write them, then a count. Exit status 1 when the
// scene has an error (render would stop), 0 when it has only warnings or nothing.
int run_check(const std::string &scene, const std::vector<std::string> &define_args) {
    std::map<std::string, std::string> defines;
    for (const std::string &d : define_args) defines.insert(split_key_value(d, "-D"));
    const std::vector<neepp::SceneProblem> problems = neepp::check_scene(scene, defines);
    int errors = 0;
    for (const neepp::SceneProblem &p : problems) {
        fmt::print("{}\n", p.text());
        errors += p.error;
    }
    fmt::print("{}: {} error{}, {} warning{}{}\n", scene, errors, errors == 1 ? "" : "s", problems.size() - errors,
               problems.size() - errors == 1 ? "" : "s", errors ? "" : ": neepp renders it");
    return errors ? 1 : 0;
}

// -I's help: each integrator's options, from the option table.
std::string options_help() {
    std::string help;
    for (const neepp::IntegratorDoc &d : neepp::integrator_docs()) {
        std::string names;
        for (const neepp::OptionDoc &o : d.options) names += (names.empty() ? "" : ", ") + o.name;
        help += "  " + d.name + ": " + names + "\n";
    }
    return help;
}

// `neepp list`: what there is to choose from, with defaults and meanings.
void print_list() {
    fmt::print("Integrators (--integrator NAME, options as -I key=value):\n");
    for (const neepp::IntegratorDoc &d : neepp::integrator_docs()) {
        fmt::print("\n  {}: {}\n", d.name, d.description);
        for (const neepp::OptionDoc &o : d.options)
            fmt::print("    {:<18} {:<12} {}{}\n", o.name, o.default_value.empty() ? "(none)" : o.default_value, o.description,
                       o.needs.empty() ? "" : " [with " + o.needs + "]");
    }
    fmt::print("\nLight samplers (-I light_sampler=NAME): ");
    std::string samplers;
    for (const std::string &n : neepp::light_sampler_names()) samplers += (samplers.empty() ? "" : ", ") + n;
    fmt::print("{}\n\nShadow-ray policies (-I shadow_rays=NAME):\n", samplers);
    for (const auto &[name, what] : neepp::shadow_ray_policy_docs()) fmt::print("  {:<16} {}\n", name, what);
    fmt::print("\nMitsuba 3 plugins a scene may use:\n");
    for (const auto &[kind, names] : neepp::supported_plugins()) fmt::print("  {:<11} {}\n", kind, neepp::supported_list(kind));
}

// The built-in scenes: beside the binary's folder (the checkout's build/../scenes, or the Python package's
// neepp/bin/../scenes), else where the checkout was when it was built.
std::string scenes_dir() {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path beside = fs::canonical("/proc/self/exe", ec).parent_path().parent_path() / "scenes";
    if (!ec && fs::exists(beside / "door-ajar" / "scene.xml")) return beside.string();
    return NEEPP_SCENES_DIR;
}

// One comparison of the demo: scene rendered with the baseline options at spp, then with the NEE++
// options for the same wall time; writes demo_<base>/<alt> images and statistics, a side-by-side PNG,
// and returns the pair's summary.
nlohmann::json demo_pair(const std::string &dir, const std::string &scene, int spp, bool quiet, const std::string &base,
                         const std::vector<std::string> &base_options, const std::string &alt,
                         const std::vector<std::string> &alt_options, const std::string &side_by_side_name,
                         const std::string &integrator = "") {
    RenderArgs a_args;
    a_args.integrator = integrator;
    a_args.scene = scenes_dir() + "/" + scene + "/scene.xml";
    a_args.output = dir + "/demo_" + base + ".exr";
    a_args.stats = dir + "/demo_" + base + ".json";
    a_args.spp = spp;
    a_args.quiet = quiet;
    a_args.integrator_options = base_options;
    Rendered a = run_render(a_args);

    RenderArgs b_args = a_args;
    b_args.output = dir + "/demo_" + alt + ".exr";
    b_args.stats = dir + "/demo_" + alt + ".json";
    b_args.spp = 0;
    b_args.time_s = a.stats["render_time_s"].get<double>();
    b_args.integrator_options = alt_options;
    Rendered b = run_render(b_args);

    neepp::write_png_srgb(dir + "/" + side_by_side_name, side_by_side(a.image, b.image));
    auto ratio = [&](const char *k) {
        double d = a.stats[k].get<double>();
        return d > 0 ? b.stats[k].get<double>() / d : 0.0;
    };
    return {{"scene", scene},
            {"equal_time_s", b_args.time_s},
            {base, a.stats},
            {alt, b.stats},
            {"spp_ratio", ratio("spp")},
            {"shadow_rays_per_sample_ratio", ratio("shadow_rays") / std::max(1e-12, ratio("spp"))},
            {"occluded_fraction", {{base, a.stats["shadow_rays_occluded"].get<double>() /
                                              std::max(1.0, a.stats["shadow_rays"].get<double>())},
                                   {alt, b.stats["shadow_rays_occluded"].get<double>() /
                                             std::max(1.0, b.stats["shadow_rays"].get<double>())}}},
            {"side_by_side", side_by_side_name}};
}

// The demo, three equal-time comparisons a first-time user can look at:
//  1. shadow-ray rejection: the built-in door-ajar scene (a room lit through a door ajar) with plain NEE,
//     then with NEE++'s best policy: more samples per pixel in the same time;
//  2. light selection: the office scene (30 lights, most behind walls) with the default light choice (a
//     light BVH), then with -I neepp=auto, which measures NEE++'s choices on a pilot and keeps the best:
//     shadow rays spent on lights that are seen;
//  3. BDPT's light-path selection: door-ajar with plain BDPT, then with NEE++ choosing, per camera path,
//     which of a pool of light paths it connects to.
void run_demo(const std::string &dir, int spp, bool quiet) {
    std::filesystem::create_directories(dir);
    nlohmann::json rejection = demo_pair(dir, "door-ajar", spp, quiet, "nee", {"shadow_rays=nee"}, "neepp",
                                         {"shadow_rays=neepp-adaptive"},  // the best policy measured
                                         "demo_side_by_side.png");
    nlohmann::json selection = demo_pair(dir, "office", spp, quiet, "lights_bvh", {}, "lights_auto", {"neepp=auto"},
                                         "demo_lights_side_by_side.png");
    // BDPT costs several path samples per sample (every vertex pair is a connection): an eighth of the
    // sample count keeps the demo's time.
    nlohmann::json bdpt = demo_pair(dir, "door-ajar", std::max(1, spp / 8), quiet, "bdpt", {}, "bdpt_neepp",
                                    {"light_paths=neepp"}, "demo_bdpt_side_by_side.png", "bdpt");
    nlohmann::json summary = {{"shadow_ray_rejection", rejection}, {"light_selection", selection},
                              {"bdpt_light_path_selection", bdpt}};
    neepp::write_file_atomically(dir + "/demo_summary.json", summary.dump(2) + "\n");
    if (!quiet) {
        fmt::print(stderr,
                   "neepp demo: in {:.2f} s, NEE reached {} spp and NEE++ {} spp ({:.2f}x), with {:.2f}x the shadow rays per "
                   "sample; see {}/demo_side_by_side.png (left NEE, right NEE++)\n",
                   rejection["equal_time_s"].get<double>(), rejection["nee"]["spp"].get<int>(),
                   rejection["neepp"]["spp"].get<int>(), rejection["spp_ratio"].get<double>(),
                   rejection["shadow_rays_per_sample_ratio"].get<double>(), dir);
        fmt::print(stderr,
                   "neepp demo: office, 30 lights, {:.2f} s each: {:.0f} % of the light BVH's shadow rays were occluded, "
                   "{:.0f} % of neepp=auto's ({}); see {}/demo_lights_side_by_side.png (left BVH, right auto)\n",
                   selection["equal_time_s"].get<double>(), 100 * selection["occluded_fraction"]["lights_bvh"].get<double>(),
                   100 * selection["occluded_fraction"]["lights_auto"].get<double>(),
                   selection["lights_auto"]["integrator"].value("neepp_picked", std::string("?")), dir);
        fmt::print(stderr,
                   "neepp demo: door-ajar with BDPT, {:.2f} s each: {:.0f} % of plain BDPT's connections were occluded, "
                   "{:.0f} % with NEE++ light-path selection; see {}/demo_bdpt_side_by_side.png (left BDPT, right "
                   "BDPT with NEE++ selection)\n",
                   bdpt["equal_time_s"].get<double>(), 100 * bdpt["occluded_fraction"]["bdpt"].get<double>(),
                   100 * bdpt["occluded_fraction"]["bdpt_neepp"].get<double>(), dir);
    }
}

// The parts of the CLI written in Python run with the project's interpreter: NEEPP_PYTHON, else the Python
// of the venv this binary was installed into by `pip install .` (VENV/lib/pythonX.Y/site-packages/neepp/bin),
// else the checkout's .venv, else python3. The checkout's python/ goes on PYTHONPATH. Does not return.
[[noreturn]] void exec_python(const std::string &what, std::vector<std::string> words) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path self = fs::canonical("/proc/self/exe", ec);
    const char *env = std::getenv("NEEPP_PYTHON");
    const fs::path installed = ec ? fs::path() : self.parent_path().parent_path().parent_path().parent_path().parent_path()
                                                        .parent_path() / "bin" / "python";
    const std::string venv = std::string(NEEPP_SOURCE_DIR) + "/.venv/bin/python";
    const std::string python = env && *env                                                      ? env
                               : !ec && self.parent_path().parent_path().filename() == "neepp" &&
                                         fs::exists(installed) ? installed.string()
                               : fs::exists(venv)              ? venv
                                                               : "python3";
    const char *old_path = std::getenv("PYTHONPATH");
    const std::string path = std::string(NEEPP_SOURCE_DIR) + "/python" + (old_path && *old_path ? std::string(":") + old_path : "");
    setenv("PYTHONPATH", path.c_str(), 1);
    words.insert(words.begin(), python);
    std::vector<char *> argv;
    for (std::string &w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    fmt::print(stderr, "neepp: error: cannot run {} for {}: {} (scripts/setup_python.sh sets up its Python)\n", python,
               what, std::strerror(errno));
    std::exit(1);
}

// `neepp compare` is neepp_tools.compare (Python: the metrics, NVIDIA FLIP, the plots and the page), told
// which neepp to render with.
[[noreturn]] void run_compare(const std::vector<std::string> &args) {
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::canonical("/proc/self/exe", ec);
    std::vector<std::string> words = {"-m", "neepp_tools.compare"};
    if (!ec) words.insert(words.end(), {"--neepp", self.string()});
    words.insert(words.end(), args.begin(), args.end());
    exec_python("neepp compare", words);
}

// `neepp view` is neepp_tools.view (Python: the web server, the page, and the renders through the neepp
// package), given its arguments as they were typed.
[[noreturn]] void run_view(const std::vector<std::string> &args) {
    std::vector<std::string> words = {"-m", "neepp_tools.view"};
    words.insert(words.end(), args.begin(), args.end());
    exec_python("neepp view", words);
}

// `neepp render --ray [ADDRESS] --workers N` is neepp.distributed's command line (the Python package),
// given the render's arguments as they were typed.
[[noreturn]] void run_distributed(int argc, char **argv) {
    std::vector<std::string> words = {"-m", "neepp.distributed"};
    bool after_render = false;
    for (int i = 1; i < argc; ++i) {
        if (after_render) words.push_back(argv[i]);
        after_render = after_render || std::string(argv[i]) == "render";
    }
    exec_python("neepp render --ray", words);
}

}  // namespace

int main(int argc, char **argv) {
    neepp::restart_with_huge_pages(argv);  // once, before anything is allocated (see huge_pages.h)
    CLI::App app{"neepp: a physically based renderer with Next Event Estimation++"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("neepp ") + NEEPP_VERSION);

    RenderArgs ra;
    auto *render = app.add_subcommand("render", "Render a Mitsuba 3 XML scene");
    render->add_option("scene", ra.scene, "Scene file (Mitsuba 3 XML)")->required()->check(CLI::ExistingFile);
    render->add_option("-o,--output", ra.output, "Output EXR (a PNG is written beside it)");
    auto *spp = render->add_option("--spp", ra.spp, "Samples per pixel (default: the scene's)")->check(CLI::Range(1, 1 << 24));
    render->add_option("--time", ra.time_s, "Render for this many seconds instead")->check(CLI::PositiveNumber)->excludes(spp);
    render->add_option("--seed", ra.seed, "Random seed (default: the scene's sampler seed)");
    render->add_option("--crop", ra.crop, "Render only the window x,y,w,h of the film (pixels; the image is w x h)")
        ->delimiter(',')
        ->expected(4);
    render->add_option("--png", ra.png, "auto: write a PNG (sRGB, clamped) beside the EXR; none: the EXR only")
        ->check(CLI::IsMember({"auto", "none"}));
    render->add_option("--threads", ra.threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
    render->add_option("-D", ra.defines, "Scene parameter override name=value (as mitsuba -D)");
    render->add_option("--integrator", ra.integrator, "Integrator (default: the scene's)");
    render->add_option("-I", ra.integrator_options, "Integrator option key=value (neepp list shows all):\n" + options_help());
    render->add_option("--sampler", ra.sampler, "Sampler: independent or sobol (default: the scene's)");
    render->add_option("--rfilter", ra.rfilter, "Override the film's reconstruction filter")
        ->check(CLI::IsMember({"box", "tent", "gaussian"}));
    render->add_option("--visibility-map", ra.visibility_map,
                       "NEE++ visibility map file: loaded if it exists and belongs to this scene, else built and saved");
    render->add_option("--stats", ra.stats, "Write statistics JSON here");
    render->add_option("--snapshots", ra.snapshots,
                       "Write the image so far into this folder at geometrically spaced times (snapshot_NNN.exr, "
                       "listed in snapshots.json with their spp and render time), for convergence plots");
    render->add_option("--checkpoint", ra.checkpoint_s,
                       "Every this many seconds, and when stopped early, save the render's state to OUTPUT.checkpoint "
                       "and write the image so far")
        ->check(CLI::PositiveNumber);
    render->add_flag("--resume", ra.resume,
                     "Continue the render saved in OUTPUT.checkpoint (same scene, options and seed) to the same image an "
                     "uninterrupted render gives");
    render->add_option("--display-server", ra.display_server,
                       "Show the render in tev (the HDR viewer) as it converges, the tev listening at HOST:PORT "
                       "(tev's default 127.0.0.1:14158): the image after each pass, a few times a second at most, "
                       "and the final one. A viewer that is absent, slow or goes away costs a warning, never the "
                       "render, and the image written is the same")
        ->type_name("HOST:PORT")
        ->check(CLI::Validator(
            [](std::string &s) {
                try {
                    neepp::parse_server_address(s);
                    return std::string();
                } catch (const std::invalid_argument &e) {
                    return std::string(e.what());
                }
            },
            ""));  // no description: the type name already says HOST:PORT
    render->add_flag("-q,--quiet", ra.quiet, "No progress bar or messages");
    std::string ray_address;
    int workers = 2;
    render->add_option("--ray", ray_address,
                       "Render on Ray workers (the Python package's neepp.distributed): on a local Ray instance "
                       "(loopback only), or on the cluster at ADDRESS")
        ->expected(0, 1);
    render->add_option("--workers", workers, "With --ray: how many workers render the image (each with --threads)")
        ->check(CLI::Range(1, 4096));

    std::string demo_dir = "neepp-demo";
    int demo_spp = 64;
    bool demo_quiet = false;
    auto *demo = app.add_subcommand("demo", "Render the built-in demo scene (a room lit through a door ajar) with NEE "
                                            "and with NEE++ at equal time, and the office scene with power and visibility-aware light selection");
    demo->add_option("-o,--output-dir", demo_dir, "Directory for the demo's images and statistics");
    demo->add_option("--spp", demo_spp, "Samples per pixel")->check(CLI::Range(1, 1 << 20));
    demo->add_flag("-q,--quiet", demo_quiet, "No progress bar or messages");

    std::string check_scene_path;
    std::vector<std::string> check_defines;
    auto *check = app.add_subcommand("check", "List every problem of a scene at once (unsupported plugins, missing "
                                              "files, properties nothing reads) without rendering it");
    check->add_option("scene", check_scene_path, "Scene file (Mitsuba 3 XML)")->required()->check(CLI::ExistingFile);
    check->add_option("-D", check_defines, "Scene parameter override name=value (as mitsuba -D)");
    auto *list = app.add_subcommand("list", "List the integrators with their options, the light samplers, the shadow-ray "
                                            "policies and the Mitsuba 3 plugins scenes may use");
    auto *compare = app.add_subcommand("compare", "Render a scene with several methods at equal time (or spp) and "
                                                  "write an HTML report: neepp compare SCENE.xml --methods path,bdpt,pssmlt "
                                                  "--time S [--reference REF.exr] -o DIR (neepp compare --help for all)");
    compare->prefix_command();  // everything after it is the Python tool's
    compare->set_help_flag();
    auto *view = app.add_subcommand("view", "Render a scene interactively in a local web page: move the camera, switch "
                                            "the integrator's options, watch the image converge and NEE++'s map keep "
                                            "learning: neepp view SCENE.xml [-D name=value] [--integrator NAME] "
                                            "[-I key=value] [--port N] [--open] (neepp view --help for all)");
    view->prefix_command();  // everything after it is the Python tool's
    view->set_help_flag();

    CLI11_PARSE(app, argc, argv);
    if (*compare) run_compare(compare->remaining());
    if (*view) run_view(view->remaining());
    if (*render && (render->count("--ray") > 0 || render->count("--workers") > 0)) run_distributed(argc, argv);
    std::signal(SIGINT, on_stop_signal);
    std::signal(SIGTERM, on_stop_signal);
    try {
        if (*render) {
            run_render(ra);
        } else if (*demo) {
            run_demo(demo_dir, demo_spp, demo_quiet);
        } else if (*list) {
            print_list();
        } else if (*check) {
            return run_check(check_scene_path, check_defines);
        }
    } catch (const std::exception &e) {
        fmt::print(stderr, "neepp: error: {}\n", e.what());
        return 1;
    }
    return g_cancel ? 128 + g_signal.load() : 0;  // the shell's convention: 130 after Ctrl-C, 143 after SIGTERM
}
