// The integrator interface: estimates the radiance arriving along a camera ray. The render loop owns
// threads, passes and time; integrators own the light transport and may keep state between passes
// (NEE++ publishes its visibility map there).
#pragma once
#include <atomic>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <nlohmann/json.hpp>
#include "neepp/base/interaction.h"
#include "neepp/base/options.h"
#include "neepp/base/pass_statistics.h"
#include "neepp/base/stats.h"

namespace neepp {

class Scene;
class Sampler;
class SplatFilm;
class SplatSink;
class RayBatch;

// What the render loop tells an integrator before a pass.
struct PassInfo {
    int pass_index = 0;
    int spp = 0;                // samples per pixel completed before this pass
    int size = 0;               // samples per pixel this pass adds
    uint64_t camera_samples = 0;  // pixels × size
    uint64_t seed = 0;
};

// What the render loop gives an integrator that renders its passes itself (PassIntegrator::render_pass).
struct PassControl {
    std::function<bool()> stop;                // true once the pass must end (cancel, time overrun)
    std::atomic<uint64_t> *samples_done = nullptr;  // samples completed this pass, for the progress bar
    // Seconds of the pass spent on one-off work (PSSMLT's bootstrap), which the body adds here: left out
    // of the speed that sizes the passes after it.
    double *one_off_s = nullptr;
};

// What every integrator is to the render loop: hooks around its passes, what it learns between them, and
// its description. How it renders a pass is its family's (below): exactly one of RayIntegrator,
// SplattingIntegrator and PassIntegrator.
class Integrator {
public:
    virtual ~Integrator() = default;
    // Called once before rendering starts (build tables, seed maps).
    virtual void prepare(const Scene &scene) {}
    // Called between passes, single-threaded, after all samples of the pass are in.
    virtual void end_pass(const Scene &scene, const PassStatistics &pass) {}
    // Whether end_pass changes what later samples do (NEE++ publishes a new map): the render loop then
    // starts with small passes, so that it learns early. Asked after prepare().
    virtual bool learns_between_passes() const { return false; }
    // Render checkpoints (--checkpoint, --resume): what end_pass has learned so far, as bytes, and its
    // restoration right after prepare(), so that a resumed render continues the one that was stopped.
    // An integrator that keeps anything between passes must carry it here.
    virtual std::string save_state() const { return {}; }
    virtual void restore_state(const Scene &scene, const std::string &state) {}
    // Distributed rendering (render ranges of sample indices on several machines): each range's render
    // continued from the state `base` and learned something (`learned`, in range order); returns the state
    // that holds what all of them learned, which the next ranges continue from.
    virtual std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const {
        return learned.empty() ? base : learned.front();
    }
    // Name and effective options, for the statistics file.
    virtual nlohmann::json describe() const = 0;
    // Extra statistics of this integrator (map size, rays skipped...), merged into the stats file.
    virtual nlohmann::json statistics() const { return nlohmann::json::object(); }
};

// Integrators that estimate the radiance arriving along each camera ray, one pixel sample at a time (path):
// the render loop's tile loop calls Li. A fast form that evaluates many camera rays at once is a side
// interface (RayBatch, integrators/ray_batch.h), which the render loop uses where batch() offers one.
class RayIntegrator : public Integrator {
public:
    virtual Color Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters) const = 0;
    // The fast form for the coming pass, or null: Li alone. Asked after prepare() and after each end_pass().
    virtual const RayBatch *batch() const { return nullptr; }
};

// Integrators whose camera samples also add to other pixels than their own (light tracing, BDPT's t = 1
// strategies): the render loop calls Li with the pass's splat film, and adds the splats to the image
// scaled by pixels / light paths.
class SplattingIntegrator : public Integrator {
public:
    virtual Color Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters,
                     SplatSink &splats) const = 0;
    // Light paths whose camera connections each camera sample splats (1: its own light path; 0 when the
    // light paths are traced apart, before the pass, as BDPT's NEE++ pool is).
    virtual double light_paths_per_sample() const { return 1; }
    // Called before each pass, from the render loop's thread arena (it may run in parallel inside): BDPT's
    // NEE++ selection traces its pool of light paths here. Returns how many light paths it splatted into
    // `splats`, which count toward the splats' normalization.
    virtual uint64_t begin_pass(const Scene &scene, const PassInfo &pass, SplatFilm &splats, RenderCounters &counters) {
        return 0;
    }
};

// Integrators that are not one path per pixel (PSSMLT) and supply the pass body themselves: the render
// loop keeps the budget, passes, progress, cancellation, checkpoints and statistics, and calls render_pass
// in place of its tile loop. A pass is pass.camera_samples samples, every one splatted; the body adds the
// samples it completes to control.samples_done as it goes (the progress bar reads it), and returns early
// once control.stop() says so. Returns how many samples it splatted: they count toward the splats'
// normalization as light paths do.
class PassIntegrator : public Integrator {
public:
    virtual uint64_t render_pass(const Scene &scene, const PassInfo &pass, SplatFilm &splats, RenderCounters &counters,
                                 const PassControl &control) = 0;
    // A factor on the splat layer that the integrator learns as the render goes (PSSMLT's normalization,
    // refined by every pass), read whenever the image is formed.
    virtual double splat_scale() const { return 1.0; }
};

// The radiance of each of a batch of camera rays, each with its own sampler (set up for its pixel and
// sample), into out: through the integrator's fast form where it has one, else Li one ray at a time.
void Li_batch(const RayIntegrator &integrator, const Scene &scene, std::span<const Ray> rays,
              std::span<Sampler *const> samplers, std::span<Color> out, RenderCounters &counters);
// Whether the integrator's samples splat: a SplattingIntegrator's or a PassIntegrator's.
bool splats(const Integrator &integrator);

}  // namespace neepp
