// Helpers for tests that render small scenes written inline as Mitsuba XML.
#pragma once
#include <gtest/gtest.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include "neepp/integrators/factory.h"
#include "neepp/loader/scene_loader.h"
#include "neepp/render/render_loop.h"

namespace neepp::testing {

using OptionMap = std::map<std::string, std::string>;

// The opening of an inline test scene: a path integrator and a perspective camera with a box-filtered film.
inline std::string scene_header_xml(int max_depth, int fov, const std::string &origin, const std::string &target,
                                    int width, int height) {
    return R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value=")" + std::to_string(max_depth) + R"("/></integrator>
  <sensor type="perspective">
    <float name="fov" value=")" + std::to_string(fov) + R"("/>
    <transform name="to_world"><lookat origin=")" + origin + R"(" target=")" + target + R"(" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value=")" + std::to_string(width) + R"("/><integer name="height" value=")" +
           std::to_string(height) + R"("/><rfilter type="box"/></film>
  </sensor>
)";
}

// Writes xml to a fresh file in the temp directory and returns its path.
// The folders are removed when the test process exits.
inline std::string write_temp_scene(const std::string &xml, const std::string &name = "scene.xml") {
    struct Folders {
        std::vector<std::filesystem::path> made;
        ~Folders() {
            std::error_code ec;
            for (const auto &d : made) std::filesystem::remove_all(d, ec);
        }
    };
    static Folders folders;
    static int counter = 0;
    auto dir = std::filesystem::temp_directory_path() / ("neepp_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    // A folder of that name is a dead process's (PIDs are reused, and a crashed test leaves its folders):
    // its files, e.g. a damaged visibility map, must not leak into this test.
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    folders.made.push_back(dir);
    auto path = dir / name;
    std::ofstream(path) << xml;
    return path.string();
}

struct RenderedImage {
    Image image;
    RenderResult result;
};

// The options given, and the scene file's integrator options that they do not set.
inline Options with_scene_options(const Scene &scene, const Options &options) {
    Options o = options;
    for (auto &[k, v] : scene.settings.integrator_options)
        if (!o.has(k)) o.set(k, v);
    return o;
}

inline RenderedImage render_scene_file(const std::string &path, int spp, uint64_t seed, const Options &options,
                                       const std::string &integrator = "path", const std::string &sampler = "independent") {
    auto scene = load_scene(path);
    auto integ = make_integrator(integrator, with_scene_options(*scene, options));
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

// A small closed room with an occluder under its ceiling light and glossy (rough plastic, rough gold),
// textured and diffuse materials, max_depth 6: where different estimators of one integral must agree.
inline const char *kGlossyRoomXml = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,1,1.9" target="0,0.8,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></bsdf>
  <bsdf type="twosided" id="checker"><bsdf type="diffuse">
    <texture name="reflectance" type="checkerboard"><rgb name="color0" value="0.8,0.2,0.2"/><rgb name="color1" value="0.2,0.2,0.8"/></texture>
  </bsdf></bsdf>
  <shape type="cube"><transform name="to_world"><scale value="2"/><translate y="1"/></transform>
    <bsdf type="twosided"><bsdf type="roughplastic"><float name="alpha" value="0.3"/><string name="distribution" value="ggx"/>
      <rgb name="diffuse_reflectance" value="0.5,0.6,0.4"/></bsdf></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.4"/><translate x="-0.5" y="0.4" z="-0.3"/></transform><ref id="checker"/></shape>
  <shape type="sphere"><point name="center" x="0.6" y="0.5" z="0.3"/><float name="radius" value="0.4"/>
    <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.2"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="2.9"/></transform>
    <ref id="white"/><emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.8" y="0.8"/><rotate x="1" angle="90"/><translate y="2.2"/></transform><ref id="white"/></shape>
</scene>)";

// Unbiasedness checks compare two estimators through coarse block means of the green channel, each
// averaged over independently seeded renders: per block, the mean over seeds and the variance of that mean.
struct BlockMoments {
    std::vector<double> mean, var;
};

inline std::vector<double> block_means(const Image &img, int bx, int by) {
    std::vector<double> blocks;
    for (int y0 = 0; y0 + by <= img.height; y0 += by)
        for (int x0 = 0; x0 + bx <= img.width; x0 += bx) {
            double sum = 0;
            for (int y = y0; y < y0 + by; ++y)
                for (int x = x0; x < x0 + bx; ++x) sum += img.at(x, y, 1);
            blocks.push_back(sum / (bx * by));
        }
    return blocks;
}

inline BlockMoments moments_over_seeds(const std::vector<std::vector<double>> &per_seed) {
    BlockMoments m;
    const size_t nb = per_seed.at(0).size(), seeds = per_seed.size();
    m.mean.assign(nb, 0);
    m.var.assign(nb, 0);
    for (size_t b = 0; b < nb; ++b) {
        for (auto &ps : per_seed) m.mean[b] += ps[b] / seeds;
        for (auto &ps : per_seed) m.var[b] += (ps[b] - m.mean[b]) * (ps[b] - m.mean[b]) / (seeds - 1);
        m.var[b] /= seeds;
    }
    return m;
}

// Block moments of one integrator over `seeds` renders of a scene file, seeded seed0 + 31 s.
inline BlockMoments block_moments(const std::string &path, const std::string &integrator, const Options &o, int seeds,
                                  int spp, uint64_t seed0) {
    std::vector<std::vector<double>> per_seed;
    for (int s = 0; s < seeds; ++s)
        per_seed.push_back(block_means(render_scene_file(path, spp, seed0 + 31 * s, o, integrator).image, 6, 6));
    return moments_over_seeds(per_seed);
}

// Two-sample z-tests per block (Bonferroni over ~12 blocks at a ~1e-3 family-wise level, with a generous
// bound for the heavier tails of few-seed variance estimates) and on the whole-image mean.
inline void expect_same_image(const BlockMoments &ref, const BlockMoments &test, const std::string &what) {
    size_t nb = ref.mean.size();
    double m_ref = 0, m_test = 0, v_ref = 0, v_test = 0;
    for (size_t b = 0; b < nb; ++b) {
        double z = (test.mean[b] - ref.mean[b]) / std::sqrt(ref.var[b] + test.var[b] + 1e-12);
        EXPECT_LT(std::abs(z), 5.0) << what << ": block " << b << " reference " << ref.mean[b] << " tested " << test.mean[b];
        m_ref += ref.mean[b] / nb; m_test += test.mean[b] / nb;
        v_ref += ref.var[b] / (nb * nb); v_test += test.var[b] / (nb * nb);
    }
    double z = (m_test - m_ref) / std::sqrt(v_ref + v_test);
    EXPECT_LT(std::abs(z), 4.0) << what << ": image mean reference " << m_ref << " tested " << m_test;
    EXPECT_GT(m_ref, 1e-3) << what << ": the scene must be lit, or the test proves nothing";
}

}  // namespace neepp::testing
