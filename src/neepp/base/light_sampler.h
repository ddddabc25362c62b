// Light selection for next event estimation. The one interface every strategy implements:
// sample(ctx, u) -> (light, pmf) and pmf(ctx, light), where pmf must be exactly reproducible from
// (ctx, light) alone because MIS needs it when a BSDF-sampled ray hits a light.
#pragma once
#include <memory>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "neepp/base/light.h"

namespace neepp {

// What a light sampler may know about the shading point.
struct LightSampleContext {
    Vec3 p;
    Vec3 n;  // geometric normal (zero for a point in a medium)
};

class LightSelectionLearner;

struct SampledLight {
    const Light *light = nullptr;
    float pmf = 0;
};

class LightSampler {
public:
    virtual ~LightSampler() = default;
    virtual SampledLight sample(const LightSampleContext &ctx, float u) const = 0;
    // Speed hook, optional: n lights for one shading point, out[i] what sample(ctx, u[i]) returns (to the
    // bit), for resampled NEE's candidates. Samplers whose choice has work common to all samples (the light
    // BVH's node importances) do it once.
    virtual void sample_many(const LightSampleContext &ctx, const float *u, int n, SampledLight *out) const {
        for (int i = 0; i < n; ++i) out[i] = sample(ctx, u[i]);
    }
    virtual float pmf(const LightSampleContext &ctx, const Light &light) const = 0;
    virtual std::string name() const = 0;
    // Called between passes, single-threaded: samplers whose tables follow the visibility map rebuild
    // them here (the next pass reads them frozen, so the pmf stays exact within a pass).
    virtual void end_pass() {}
    // Side interface of samplers that learn from NEE's own samples (light_selection_learner.h), or null:
    // the integrator then reports nothing.
    virtual LightSelectionLearner *learner() { return nullptr; }
    const LightSelectionLearner *learner() const { return const_cast<LightSampler *>(this)->learner(); }
    // Table counts, build times... for the statistics file.
    virtual nlohmann::json statistics() const { return nlohmann::json::object(); }
};

}  // namespace neepp
