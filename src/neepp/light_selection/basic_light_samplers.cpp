#include "neepp/light_selection/basic_light_samplers.h"

namespace neepp {

SampledLight UniformLightSampler::sample(const LightSampleContext &, float u) const {
    if (lights_.empty()) return {};
    size_t n = lights_.size();
    size_t i = std::min(size_t(u * float(n)), n - 1);
    return {lights_[i], 1.f / float(n)};
}

std::vector<float> power_fractions(const std::vector<const Light *> &lights) {
    double total = 0;
    for (const Light *l : lights) total += std::max(0.f, luminance(l->power()));
    std::vector<float> out;
    for (const Light *l : lights)
        out.push_back(total > 0 ? float(std::max(0.f, luminance(l->power())) / total) : 1.f / float(lights.size()));
    return out;
}

LightDistribution::LightDistribution(const std::vector<const Light *> &lights, const std::vector<float> &weights)
    : distribution_(weights) {
    uint32_t max_index = 0;
    for (const Light *l : lights) max_index = std::max(max_index, l->index);
    pmf_by_index_.assign(lights.empty() ? 0 : max_index + 1, 0.f);
    for (size_t i = 0; i < lights.size(); ++i) pmf_by_index_[lights[i]->index] = distribution_.pmf(uint32_t(i));
}

SampledLight LightDistribution::sample(const std::vector<const Light *> &lights, float u) const {
    if (lights.empty()) return {};
    // One light (most test scenes): no search, and the pmf is still the one pmf() reads back.
    const Light *l = lights.size() == 1 ? lights[0] : lights[distribution_.sample_discrete(u)];
    return {l, pmf(*l)};
}

// Defined here, beside LightDistribution::sample, so that it is inlined into the one copy of this.
SampledLight PowerLightSampler::sample(const LightSampleContext &, float u) const { return distribution_.sample(lights_, u); }

PowerLightSampler::PowerLightSampler(std::vector<const Light *> lights)
    : lights_(std::move(lights)), distribution_(lights_, power_fractions(lights_)) {}

}  // namespace neepp
