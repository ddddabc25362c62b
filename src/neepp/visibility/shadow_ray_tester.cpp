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

void trace_shadow_rays16(const Scene &scene, const Ray *const *rays, int n, bool *occluded, RenderCounters &counters) {
    uint64_t t0 = read_ticks();
    scene.occluded16(rays, n, occluded);
    counters.occlusion_ticks += read_ticks() - t0;
    counters.shadow_rays += uint64_t(n);
    for (int i = 0; i < n; ++i) counters.shadow_rays_occluded += occluded[i];
}

float test_visibility(const ShadowRayTester &tester, const Scene &scene, const ShadowQuery &q, Sampler &sampler,
                      RenderCounters &counters) {
    const ShadowTest test = tester.begin_test(q, sampler, counters);
    if (!test.trace) return test.if_skipped;
    const bool occluded = trace_shadow_ray(scene, q.ray, counters);
    tester.end_test(test, occluded);
    return test.weight(occluded);
}

}  // namespace neepp
