// Helpers for tests that render small scenes written inline as Mitsuba XML.
#pragma once
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include "neepp/integrators/integrator.h"
#include "neepp/loader/scene_loader.h"
#include "neepp/render/render_loop.h"

namespace neepp::testing {

using OptionMap = std::map<std::string, std::string>;

// Writes xml to a fresh file in the temp directory and returns its path.
inline std::string write_temp_scene(const std::string &xml, const std::string &name = "scene.xml") {
    static int counter = 0;
    auto dir = std::filesystem::temp_directory_path() / ("neepp_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(dir);
    auto path = dir / name;
    std::ofstream(path) << xml;
    return path.string();
}

struct RenderedImage {
    Image image;
    RenderResult result;
};

inline RenderedImage render_scene_file(const std::string &path, int spp, uint64_t seed, const Options &options,
                                       const std::string &integrator = "path", const std::string &sampler = "independent") {
    auto scene = load_scene(path);
    Options o = options;
    for (auto &[k, v] : scene->settings.integrator_options)
        if (!o.has(k)) o.set(k, v);
    auto integ = make_integrator(integrator, o);
    RenderJob job;
    job.spp = spp;
    job.seed = seed;
    job.sampler = sampler;
    RenderResult r = render(*scene, *integ, job);
    return {r.image, r};
}

// Mean and standard error of the per-pixel means over a set of pixels (one channel).
struct MeanStderr {
    double mean = 0, stderr_ = 0;
};
inline MeanStderr pixel_statistics(const Image &img, int channel) {
    double s = 0, s2 = 0;
    size_t n = size_t(img.width) * img.height;
    for (size_t i = 0; i < n; ++i) {
        double v = img.data[i * img.channels + channel];
        s += v;
        s2 += v * v;
    }
    double mean = s / double(n), var = std::max(0.0, s2 / double(n) - mean * mean);
    return {mean, std::sqrt(var / double(n))};
}

}  // namespace neepp::testing
