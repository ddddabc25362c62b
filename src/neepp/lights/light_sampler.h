// Light selection for next event estimation. The one interface every strategy implements:
// sample(ctx, u) -> (light, pmf) and pmf(ctx, light), where pmf must be exactly reproducible from
// (ctx, light) alone because MIS needs it when a BSDF-sampled ray hits a light.
#pragma once
#include <memory>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "neepp/lights/light.h"
#include "neepp/math/distribution.h"

namespace neepp {

// What a light sampler may know about the shading point.
struct LightSampleContext {
    Vec3 p;
    Vec3 n;  // geometric normal (zero for a point in a medium)
};

struct SampledLight {
    const Light *light = nullptr;
    float pmf = 0;
};

class LightSampler {
public:
    virtual ~LightSampler() = default;
    virtual SampledLight sample(const LightSampleContext &ctx, float u) const = 0;
    // n lights for one shading point, out[i] what sample(ctx, u[i]) returns (to the bit): for resampled
    // NEE's candidates. Samplers whose choice has work common to all samples (the light BVH's node
    // importances) do it once.
    virtual void sample_many(const LightSampleContext &ctx, const float *u, int n, SampledLight *out) const {
        for (int i = 0; i < n; ++i) out[i] = sample(ctx, u[i]);
    }
    virtual float pmf(const LightSampleContext &ctx, const Light &light) const = 0;
    virtual std::string name() const = 0;
    // Called between passes, single-threaded: samplers whose tables follow the visibility map rebuild
    // them here (the next pass reads them frozen, so the pmf stays exact within a pass).
    virtual void end_pass() {}
    // Table counts, build times... for the statistics file.
    virtual nlohmann::json statistics() const { return nlohmann::json::object(); }
};

// Each light's share of the total emitted power (luminance of Light::power()), in `lights` order; uniform
// when no light has power (e.g. black textures), so every light stays selectable.
std::vector<float> power_fractions(const std::vector<const Light *> &lights);

// A fixed discrete distribution over a list of lights whose pmf is read back by Light::index (what a
// sampler's pmf(ctx, light) receives): sampling reports exactly the float pmf() returns.
class LightDistribution {
public:
    LightDistribution() = default;
    // weights: one per light of `lights`, non-negative, at least one positive.
    LightDistribution(const std::vector<const Light *> &lights, const std::vector<float> &weights);
    // A light of `lights` (the list given to the constructor) with its pmf.
    SampledLight sample(const std::vector<const Light *> &lights, float u) const;
    float pmf(const Light &light) const {
        return light.index < pmf_by_index_.size() ? pmf_by_index_[light.index] : 0.f;
    }
    const std::vector<float> &pmf_by_index() const { return pmf_by_index_; }

private:
    Distribution1D distribution_;      // over the list's order
    std::vector<float> pmf_by_index_;  // by Light::index
};

class UniformLightSampler final : public LightSampler {
public:
    explicit UniformLightSampler(std::vector<const Light *> lights) : lights_(std::move(lights)) {}
    SampledLight sample(const LightSampleContext &, float u) const override;
    float pmf(const LightSampleContext &, const Light &) const override {
        return lights_.empty() ? 0.f : 1.f / float(lights_.size());
    }
    std::string name() const override { return "uniform"; }

private:
    std::vector<const Light *> lights_;
};

// Chooses lights proportionally to their emitted power (luminance of Light::power()).
class PowerLightSampler final : public LightSampler {
public:
    explicit PowerLightSampler(std::vector<const Light *> lights);
    SampledLight sample(const LightSampleContext &, float u) const override { return distribution_.sample(lights_, u); }
    float pmf(const LightSampleContext &, const Light &light) const override { return distribution_.pmf(light); }
    std::string name() const override { return "power"; }

private:
    std::vector<const Light *> lights_;
    LightDistribution distribution_;
};

}  // namespace neepp
