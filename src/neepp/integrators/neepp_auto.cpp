#include "neepp/integrators/neepp_auto.h"

#include <atomic>
#include <chrono>
#include <optional>
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include "neepp/base/stats.h"
#include "neepp/integrators/path.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/neepp_shadow_rays.h"

namespace neepp {

namespace {

bool several_lights(const Scene &scene) { return scene.lights().size() > 1; }

// The NEE++ component of a candidate that keeps a visibility map, or null.
NeeppShadowRays *map_keeper(Integrator &integrator) {
    auto *path = dynamic_cast<PathIntegrator *>(&integrator);
    return path ? dynamic_cast<NeeppShadowRays *>(&path->shadow_rays()) : nullptr;
}

// The pilot: kPilotSpp samples of each pixel of a grid over the film, through the fast form as the render
// loop calls it. The numbers depend on (pixel, sample) only, so every candidate sees the same camera
// rays and, wherever its choices agree with another's, the same paths: the differences between their
// variances are less noisy than the variances.
struct PilotFigures {
    std::vector<double> mean, variance;  // per pilot pixel, of its luminance; variance per sample
    double seconds_per_sample = 0;
    double sample_variance = 0;  // per sample, of a pixel's luminance (PassStatistics::sample_variance)
};

PilotFigures run_pilot(const Scene &scene, const RayIntegrator &integrator, int first_sample) {
    const Camera &cam = scene.camera;
    const int gx = std::min(AutoIntegrator::kPilotGrid, cam.width), gy = std::min(AutoIntegrator::kPilotGrid, cam.height);
    constexpr int K = AutoIntegrator::kPilotSpp;
    std::vector<double> mean(size_t(gx) * gy), var(size_t(gx) * gy);
    std::atomic<int64_t> cpu_ns{0};
    const IndependentSampler prototype(0x9117ull);
    tbb::parallel_for(0, gy, [&](int j) {
        const double t0 = cpu_seconds(CpuClock::thread);
        RenderCounters counters;  // the pilot's rays are not the render's
        std::vector<std::unique_ptr<Sampler>> owned;
        std::vector<Sampler *> samplers;
        for (int k = 0; k < K; ++k) samplers.push_back(owned.emplace_back(prototype.clone()).get());
        std::vector<Ray> rays(K);
        std::vector<Color> out(K);
        const int y = int((j + 0.5) * cam.height / gy);
        for (int i = 0; i < gx; ++i) {
            const int x = int((i + 0.5) * cam.width / gx);
            for (int k = 0; k < K; ++k) {
                Sampler &s = *samplers[k];
                s.start_sample(uint32_t(x + cam.crop_x), uint32_t(y + cam.crop_y), uint32_t(first_sample + k));
                const Vec2 jitter = s.next_2d();
                const Vec2 lens = cam.has_lens() ? s.next_2d() : Vec2(0.5f, 0.5f);
                rays[k] = cam.pixel_ray(x, y, jitter, lens);
            }
            Li_batch(integrator, scene, rays, samplers, out, counters);
            double m = 0, m2 = 0;
            for (const Color &c : out) {
                const double l = is_finite(c) ? double(luminance(c)) : 0.0;
                m += l;
                m2 += l * l;
            }
            m /= K;
            const size_t p = size_t(j) * gx + i;
            mean[p] = m;
            var[p] = std::max(0.0, (m2 - K * m * m) / (K - 1));
        }
        cpu_ns += int64_t((cpu_seconds(CpuClock::thread) - t0) * 1e9);
    });
    PilotFigures f;
    double sum_var = 0;
    for (double v : var) sum_var += v;
    f.sample_variance = sum_var / double(var.size());
    f.seconds_per_sample = double(cpu_ns.load()) * 1e-9 / (double(mean.size()) * K);
    f.mean = std::move(mean);
    f.variance = std::move(var);
    return f;
}

// The relative variance the benchmarks and EVALUATION.md measure, mean over pixels of Var / (mean² + 0.01),
// read from each candidate's pilot. The pixels' means are pooled over the candidates (each is unbiased):
// the weights 1 / (mean² + 0.01) are then the same for every candidate, and do not favour one whose own
// few samples happened to overestimate a dark pixel. Summed variance over squared mean, the measure before
// it, let the bright pixels decide, where light choice changes little; it missed smoke-plume's 1.9x.
std::vector<double> relative_variances(const std::vector<PilotFigures> &figures) {
    constexpr double eps = 0.01;
    const size_t n = figures.front().mean.size();
    std::vector<double> result(figures.size(), 0.0);
    for (size_t p = 0; p < n; ++p) {
        double m = 0;
        for (const PilotFigures &f : figures) m += f.mean[p];
        m /= double(figures.size());
        const double w = 1.0 / (m * m + eps);
        for (size_t c = 0; c < figures.size(); ++c) result[c] += w * figures[c].variance[p];
    }
    for (double &r : result) r /= double(n);
    return result;
}

}  // namespace

const std::vector<AutoCandidate> &auto_candidates(bool guiding) {
    static const std::vector<AutoCandidate> candidates = {
        {"nee", {}, [](const Scene &) { return true; }},
        // Choices between lights by what each gives every voxel of the scene, without the map, then with
        // it (NEE++'s visibility-aware selection, paper §3); the default light BVH knows bounds only.
        {"light-spatial", {{"light_sampler", "spatial-oriented"}}, several_lights},
        {"light-visibility", {{"light_sampler", "visibility"}}, several_lights},
        // Not candidates: within_light=visibility and shadow_rays=neepp-adaptive. Their pilot figures do
        // not predict a render's (their variance comes from rare bright paths that a pilot sees or misses),
        // and where they win a whole render they win by less than the margin that keeps the pilot's noise
        // from picking a loser (docs/neepp.md has the measurements).
    };
    // Guiding only where asked: it applies on every scene, so a scene with one light, which runs no pilot
    // by default, would pay one (at 64 spp about 5 % of classroom's render), and on none of the scenes
    // measured did guiding beat plain NEE (docs/performance.md). Its guide learns from three pilot passes
    // before it is measured: far less than a render's passes teach it, so the pilot underrates it.
    static const std::vector<AutoCandidate> with_guiding = [] {
        std::vector<AutoCandidate> c = candidates;
        c.push_back({"guided", {{"guiding", "sdtree"}}, [](const Scene &) { return true; }, 3});
        return c;
    }();
    return guiding ? with_guiding : candidates;
}

AutoIntegrator::AutoIntegrator(std::vector<AutoCandidate> candidates, Make make)
    : candidates_(std::move(candidates)), make_(std::move(make)) {
    chosen_integrator_ = make_(candidates_.front());  // until prepare has measured
}

void AutoIntegrator::prepare(const Scene &scene) {
    pilot_.clear();
    // With nothing to choose between, no pilot: plain NEE at no cost.
    size_t applicable = 0;
    for (const AutoCandidate &c : candidates_) applicable += c.applies(scene) ? 1 : 0;
    if (applicable <= 1) {
        chosen_ = 0;
        chosen_integrator_ = make_(candidates_.front());
        chosen_integrator_->prepare(scene);
        pilot_.push_back({candidates_.front().name, 0, 0, 1.0, 0});
        why_ = "one light: nothing to choose between";
        return;
    }
    // Every applicable candidate is prepared and runs the pilot; they are kept until all have run, since
    // each one's relative variance is weighed by the pixel means of all.
    std::vector<size_t> index;
    std::vector<std::unique_ptr<RayIntegrator>> prepared;
    // The map is seeded once, by the first candidate that seeds one in prepare; the others start from a
    // copy of it, as it was before any of them learned.
    std::optional<std::pair<VoxelGrid, VisibilityMap>> seeded;
    for (size_t k = 0; k < candidates_.size(); ++k) {
        if (!candidates_[k].applies(scene)) continue;
        std::unique_ptr<RayIntegrator> integrator = make_(candidates_[k]);
        NeeppShadowRays *keeper = map_keeper(*integrator);
        if (keeper && seeded) keeper->adopt_map(seeded->first, seeded->second);
        // Prepared, then a first pilot pass that is not measured: what a candidate builds on first use
        // (per-voxel tables) and what it decides after its first pass (whether to reject, the
        // calibration, the map learned from its rays) are behind it, as they are for most of a render.
        const auto t0 = std::chrono::steady_clock::now();
        integrator->prepare(scene);
        if (keeper && !seeded && keeper->map().pair_count() > 0) seeded.emplace(keeper->grid(), keeper->map());
        for (int w = 0; w < candidates_[k].warm_up_passes; ++w) {
            // Sample indices past the measured passes' beyond the first: no two passes share numbers.
            const int first = w == 0 ? 0 : (kPilotPasses + w) * kPilotSpp;
            const PilotFigures warm_up = run_pilot(scene, *integrator, first);
            integrator->end_pass(scene, PassStatistics{w, (w + 1) * kPilotSpp, warm_up.sample_variance});
        }
        AutoPilotResult r;
        r.name = candidates_[k].name;
        r.prepare_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        pilot_.push_back(r);
        index.push_back(k);
        prepared.push_back(std::move(integrator));
    }
    // The measured passes, the candidates taking turns: a machine that slows down for a while (another
    // process, a frequency step) slows them alike, and the variance is read from kPilotPasses × kPilotSpp
    // samples per pixel, which one pass's eight too often under- or overestimated. No candidate learns
    // between them: a pass's end rebuilds the light choice's tables, a cost a pilot pass of 48² pixels
    // would bear far more than a render's passes do.
    const int gx = std::min(kPilotGrid, scene.camera.width), gy = std::min(kPilotGrid, scene.camera.height);
    std::vector<PilotFigures> figures(prepared.size());
    for (PilotFigures &f : figures) f.mean.assign(size_t(gx) * gy, 0.0), f.variance.assign(size_t(gx) * gy, 0.0);
    for (int pass = 1; pass <= kPilotPasses; ++pass)
        for (size_t c = 0; c < prepared.size(); ++c) {
            const PilotFigures f = run_pilot(scene, *prepared[c], pass * kPilotSpp);
            for (size_t p = 0; p < f.mean.size(); ++p) {
                figures[c].mean[p] += f.mean[p] / kPilotPasses;
                figures[c].variance[p] += f.variance[p] / kPilotPasses;
            }
            figures[c].seconds_per_sample += f.seconds_per_sample / kPilotPasses;
        }
    for (size_t c = 0; c < prepared.size(); ++c) pilot_[c].seconds_per_sample = figures[c].seconds_per_sample;
    const std::vector<double> relvar = relative_variances(figures);
    size_t best = 0;  // plain NEE's, the first
    for (size_t c = 0; c < pilot_.size(); ++c) {
        AutoPilotResult &r = pilot_[c];
        r.relative_variance = relvar[c];
        const double product = r.relative_variance * r.seconds_per_sample;
        r.efficiency = product > 0 ? 1.0 / product : 0.0;
        if (c > 0 && r.efficiency > pilot_[best].efficiency && (best > 0 || r.efficiency > kMargin * pilot_[0].efficiency))
            best = c;
    }
    const double nee_efficiency = pilot_[0].efficiency;
    const double best_ratio = nee_efficiency > 0 ? pilot_[best].efficiency / nee_efficiency : 0.0;
    for (AutoPilotResult &r : pilot_) r.efficiency = nee_efficiency > 0 ? r.efficiency / nee_efficiency : 0.0;
    chosen_ = index[best];
    chosen_integrator_ = std::move(prepared[best]);
    if (best == 0)
        why_ = fmt::format("no candidate reached {:.2f}x plain NEE's efficiency in the pilot", kMargin);
    else
        why_ = fmt::format("{} had the best efficiency in the pilot, {:.2f}x plain NEE's (at least {:.2f}x needed)",
                           picked(), best_ratio, kMargin);
}

void AutoIntegrator::choose(const Scene &scene, size_t k) {
    if (k == chosen_ && chosen_integrator_) return;
    chosen_integrator_ = make_(candidates_[k]);
    chosen_integrator_->prepare(scene);
    chosen_ = k;
}

std::string AutoIntegrator::save_state() const { return picked() + '\n' + chosen().save_state(); }

namespace {
// (candidate name, the candidate's own state) of a saved state.
std::pair<std::string, std::string> split_state(const std::string &state) {
    const size_t nl = state.find('\n');
    if (nl == std::string::npos) throw std::invalid_argument("neepp=auto: the saved integrator state has no candidate name");
    return {state.substr(0, nl), state.substr(nl + 1)};
}
}  // namespace

void AutoIntegrator::restore_state(const Scene &scene, const std::string &state) {
    const auto [name, inner] = split_state(state);
    size_t k = 0;
    while (k < candidates_.size() && candidates_[k].name != name) ++k;
    if (k == candidates_.size()) throw std::invalid_argument("neepp=auto: the saved state names no candidate ('" + name + "')");
    if (k != chosen_) why_ = "continues the render that picked " + name;
    choose(scene, k);
    chosen().restore_state(scene, inner);
}

std::string AutoIntegrator::merge_states(const std::string &base, const std::vector<std::string> &learned) const {
    if (learned.empty()) return base;
    const std::string name = split_state(learned.front()).first;
    std::vector<std::string> inner;
    for (const std::string &s : learned) {
        auto [n, in] = split_state(s);
        if (n != name) throw std::invalid_argument("neepp=auto: the ranges picked different candidates");
        inner.push_back(std::move(in));
    }
    const std::string base_inner = base.empty() ? std::string() : split_state(base).second;
    return name + '\n' + chosen().merge_states(base_inner, inner);
}

nlohmann::json AutoIntegrator::describe() const {
    nlohmann::json j = chosen().describe();
    j["neepp"] = "auto";
    j["neepp_picked"] = picked();
    return j;
}

nlohmann::json AutoIntegrator::statistics() const {
    nlohmann::json j = chosen().statistics();
    nlohmann::json pilot = nlohmann::json::array();
    for (const AutoPilotResult &r : pilot_)
        pilot.push_back({{"candidate", r.name}, {"relative_variance", r.relative_variance},
                         {"seconds_per_sample", r.seconds_per_sample}, {"efficiency_vs_nee", r.efficiency},
                         {"prepare_s", r.prepare_s}});
    j["neepp_auto"] = {{"picked", picked()}, {"why", why_}, {"pilot", pilot},
                       {"pilot_pixels", "up to " + std::to_string(kPilotGrid) + "x" + std::to_string(kPilotGrid)},
                       {"pilot_spp", kPilotSpp}, {"margin", kMargin}};
    return j;
}

}  // namespace neepp
