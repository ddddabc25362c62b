#include "neepp/base/integrator.h"

#include <stdexcept>
#include "neepp/base/ray_batch.h"

namespace neepp {

void Li_batch(const RayIntegrator &integrator, const Scene &scene, std::span<const Ray> rays,
              std::span<Sampler *const> samplers, std::span<Color> out, RenderCounters &counters) {
    if (const RayBatch *batch = integrator.batch()) {
        batch->Li_batch(scene, rays, samplers, out, counters);
        return;
    }
    for (size_t i = 0; i < rays.size(); ++i) out[i] = integrator.Li(scene, rays[i], *samplers[i], counters);
}

Color Li_sample(const Integrator &integrator, const Scene &scene, const Ray &ray, Sampler &sampler,
                RenderCounters &counters, SplatSink &splats) {
    if (const auto *s = dynamic_cast<const SplattingIntegrator *>(&integrator))
        return s->Li(scene, ray, sampler, counters, splats);
    if (const auto *r = dynamic_cast<const RayIntegrator *>(&integrator)) {
        // The integrator's own form: the fast one where it has one, a batch of this one ray.
        Sampler *const samplers[1] = {&sampler};
        Color L;
        Li_batch(*r, scene, std::span<const Ray>(&ray, 1), samplers, std::span<Color>(&L, 1), counters);
        return L;
    }
    throw std::invalid_argument("integrator '" + integrator.describe().value("name", std::string()) +
                                "' renders whole passes, not one camera sample at a time");
}

bool splats(const Integrator &integrator) {
    return dynamic_cast<const SplattingIntegrator *>(&integrator) || dynamic_cast<const PassIntegrator *>(&integrator);
}

}  // namespace neepp
