#include "neepp/visibility/shadow_ray_tester.h"

#include "neepp/scene/scene.h"

namespace neepp {

bool trace_shadow_ray(const Scene &scene, const Ray &ray, RenderCounters &counters) {
    uint64_t t0 = read_ticks();
    bool blocked = scene.occluded(ray);
    counters.occlusion_ticks += read_ticks() - t0;
    ++counters.shadow_rays;
    counters.shadow_rays_occluded += blocked;
    return blocked;
}

float TraceAllShadowRays::visibility(const Scene &scene, const ShadowQuery &q, Sampler &,
                                     RenderCounters &counters) const {
    return trace_shadow_ray(scene, q.ray, counters) ? 0.f : 1.f;
}

}  // namespace neepp
