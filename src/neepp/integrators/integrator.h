// The integrator interface: estimates the radiance arriving along a camera ray. The render loop owns
// threads, passes and time; integrators own the light transport and may keep state between passes
// (NEE++ publishes its visibility map there).
#pragma once
#include <memory>
#include <span>
#include <string>
#include <nlohmann/json.hpp>
#include "neepp/integrators/options.h"
#include "neepp/render/pass_statistics.h"
#include "neepp/render/stats.h"
#include "neepp/scene/interaction.h"

namespace neepp {

class Scene;
class Sampler;

class Integrator {
public:
    virtual ~Integrator() = default;
    // Called once before rendering starts (build tables, seed maps).
    virtual void prepare(const Scene &scene) {}
    virtual Color Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters) const = 0;
    // The same for a batch of camera rays, each with its own sampler (set up for its pixel and sample),
    // results in out. The default calls Li for each; an integrator that gains from having many paths in
    // flight (to hide memory latency) overrides it, and must give exactly what Li gives.
    virtual void Li_batch(const Scene &scene, std::span<const Ray> rays, std::span<Sampler *const> samplers,
                          std::span<Color> out, RenderCounters &counters) const {
        for (size_t i = 0; i < rays.size(); ++i) out[i] = Li(scene, rays[i], *samplers[i], counters);
    }
    // Called between passes, single-threaded, after all samples of the pass are in.
    virtual void end_pass(const Scene &scene, const PassStatistics &pass) {}
    // Whether end_pass changes what later samples do (NEE++ publishes a new map): the render loop then
    // starts with small passes, so that it learns early. Asked after prepare().
    virtual bool learns_between_passes() const { return false; }
    // Name and effective options, for the statistics file.
    virtual nlohmann::json describe() const = 0;
    // Extra statistics of this integrator (map size, rays skipped...), merged into the stats file.
    virtual nlohmann::json statistics() const { return nlohmann::json::object(); }
};

// Creates an integrator by name ("path") from its options; throws on unknown names or unused options.
std::unique_ptr<Integrator> make_integrator(const std::string &name, const Options &options);

}  // namespace neepp
