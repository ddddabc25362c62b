// The one place that traces shadow rays. Every integrator asks it "is the light sample visible from the
// shading point, and with what weight?"; it counts the rays and their time, and is where NEE++'s
// shadow-ray policies (Russian-roulette rejection driven by the visibility map) plug in.
#pragma once
#include <string>
#include "neepp/render/stats.h"
#include "neepp/scene/interaction.h"

namespace neepp {

class Scene;
class Sampler;

// Everything a policy may use to decide whether to trace: the ray, both end points, and the unoccluded
// contribution the sample would add (for contribution-aware policies).
struct ShadowQuery {
    Ray ray;
    Vec3 from, to;
    Color unoccluded;  // contribution if visible (throughput × f × Le / pdf, MIS included)
};

class ShadowRayTester {
public:
    virtual ~ShadowRayTester() = default;
    // Returns the weight by which the unoccluded contribution is to be multiplied: 0 if occluded (or
    // rejected), 1 if visible, 1/q for a ray traced with probability q. Must be unbiased: E[weight] = V.
    virtual float visibility(const Scene &scene, const ShadowQuery &q, Sampler &sampler,
                             RenderCounters &counters) const = 0;
    virtual std::string policy() const = 0;
};

// Plain next event estimation: every shadow ray is traced.
class TraceAllShadowRays final : public ShadowRayTester {
public:
    float visibility(const Scene &scene, const ShadowQuery &q, Sampler &sampler, RenderCounters &counters) const override;
    std::string policy() const override { return "nee"; }
};

// Traces one occlusion query and accounts for it; the building block of every policy.
bool trace_shadow_ray(const Scene &scene, const Ray &ray, RenderCounters &counters);

}  // namespace neepp
