// The shadow-ray tester of plain next event estimation, and the tracing every tester's rays go through.
#pragma once
#include "neepp/base/shadow_ray_tester.h"

namespace neepp {

// Plain next event estimation: every shadow ray is traced.
class TraceAllShadowRays final : public ShadowRayTester {
public:
    ShadowTest begin_test(const ShadowQuery &, Sampler &, RenderCounters &) const override { return {}; }
    bool reads_contribution() const override { return false; }
    std::string policy() const override { return "nee"; }
};

// One query tested: the tester decides, the ray is traced if it asks, the tester learns the outcome;
// returns the weight of the unoccluded contribution (ShadowRayTester::begin_test).
float test_visibility(const ShadowRayTester &tester, const Scene &scene, const ShadowQuery &q, Sampler &sampler,
                      RenderCounters &counters);
// Traces one occlusion query and accounts for it; the building block of every policy.
bool trace_shadow_ray(const Scene &scene, const Ray &ray, RenderCounters &counters);
// The same for up to 16 rays as one Embree packet; occluded[i] receives ray i's answer.
void trace_shadow_rays16(const Scene &scene, const Ray *const *rays, int n, bool *occluded, RenderCounters &counters);

}  // namespace neepp
