#include "neepp/base/integrator.h"

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

bool splats(const Integrator &integrator) {
    return dynamic_cast<const SplattingIntegrator *>(&integrator) || dynamic_cast<const PassIntegrator *>(&integrator);
}

}  // namespace neepp
