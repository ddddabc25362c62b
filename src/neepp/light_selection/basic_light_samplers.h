// The two light samplers that know nothing of the shading point: uniform and by emitted power, and the
// table of one fixed distribution over lights that the others build theirs from.
#pragma once
#include <vector>
#include "neepp/base/light_sampler.h"
#include "neepp/math/distribution.h"

namespace neepp {

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
    SampledLight sample(const LightSampleContext &, float u) const override;
    float pmf(const LightSampleContext &, const Light &light) const override { return distribution_.pmf(light); }
    std::string name() const override { return "power"; }

private:
    std::vector<const Light *> lights_;
    LightDistribution distribution_;
};

}  // namespace neepp
