#include "neepp/lights/light_sampler.h"

namespace neepp {

SampledLight UniformLightSampler::sample(const LightSampleContext &, float u) const {
    if (lights_.empty()) return {};
    size_t n = lights_.size();
    size_t i = std::min(size_t(u * float(n)), n - 1);
    return {lights_[i], 1.f / float(n)};
}

PowerLightSampler::PowerLightSampler(std::vector<const Light *> lights) : lights_(std::move(lights)) {
    std::vector<float> weights;
    uint32_t max_index = 0;
    for (const Light *l : lights_) {
        weights.push_back(std::max(0.f, luminance(l->power())));
        max_index = std::max(max_index, l->index);
    }
    // A scene whose lights all report zero power (e.g. black textures) falls back to uniform selection.
    bool any = false;
    for (float w : weights) any |= w > 0;
    if (!any)
        for (float &w : weights) w = 1.f;
    distribution_ = Distribution1D(weights);
    pmf_by_index_.assign(lights_.empty() ? 0 : max_index + 1, 0.f);
    for (size_t i = 0; i < lights_.size(); ++i) pmf_by_index_[lights_[i]->index] = distribution_.pmf(uint32_t(i));
}

SampledLight PowerLightSampler::sample(const LightSampleContext &, float u) const {
    if (lights_.empty()) return {};
    float pmf;
    uint32_t i = distribution_.sample_discrete(u, &pmf);
    return {lights_[i], pmf};
}

float PowerLightSampler::pmf(const LightSampleContext &, const Light &light) const {
    return light.index < pmf_by_index_.size() ? pmf_by_index_[light.index] : 0.f;
}

}  // namespace neepp
