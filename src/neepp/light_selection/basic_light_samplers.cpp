#include "neepp/light_selection/basic_light_samplers.h"

#include <algorithm>
#include <cmath>

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

namespace light_table {

void fill(const std::vector<float> &weights, double *block) {
    const size_t n = weights.size();
    double *cdf = block, *pmf = block + n + 1;
    double sum = 0;
    cdf[0] = 0;
    for (size_t i = 0; i < n; ++i) {
        const float w = weights[i] >= 0 && std::isfinite(weights[i]) ? weights[i] : 0.f;
        sum += w;
        cdf[i + 1] = sum;
        pmf[i] = w;
    }
    const float total = float(sum);
    if (sum > 0)
        for (size_t i = 0; i <= n; ++i) cdf[i] /= sum;
    for (size_t i = 0; i < n; ++i) pmf[i] = total > 0 ? float(pmf[i]) / total : 0.f;
}

size_t sample(const double *block, size_t n, float u, float &pmf_out) {
    const double *cdf = block;
    size_t i = 0;
    if (n > 1) {
        // The first entry whose cdf passes u; an entry of weight 0 (its cdf does not rise) is never drawn.
        i = std::min(size_t(std::upper_bound(cdf + 1, cdf + n + 1, double(u)) - cdf - 1), n - 1);
        while (i > 0 && block[n + 1 + i] == 0) --i;  // u at the top edge
    }
    pmf_out = pmf(block, n, i);
    return i;
}

}  // namespace light_table

LightDistribution::LightDistribution(const std::vector<const Light *> &lights, const std::vector<float> &weights)
    : block_(light_table::block_size(weights.size())) {
    light_table::fill(weights, block_.data());
    uint32_t max_index = 0;
    for (const Light *l : lights) max_index = std::max(max_index, l->index);
    pmf_by_index_.assign(lights.empty() ? 0 : max_index + 1, 0.f);
    for (size_t i = 0; i < lights.size(); ++i) pmf_by_index_[lights[i]->index] = light_table::pmf(block_.data(), lights.size(), i);
}

SampledLight LightDistribution::sample(const std::vector<const Light *> &lights, float u) const {
    if (lights.empty()) return {};
    float pmf;
    const size_t i = light_table::sample(block_.data(), lights.size(), u, pmf);
    return {lights[i], pmf};
}

// Defined here, beside LightDistribution::sample, so that it is inlined into the one copy of this.
SampledLight PowerLightSampler::sample(const LightSampleContext &, float u) const { return distribution_.sample(lights_, u); }

PowerLightSampler::PowerLightSampler(std::vector<const Light *> lights)
    : lights_(std::move(lights)), distribution_(lights_, power_fractions(lights_)) {}

}  // namespace neepp
