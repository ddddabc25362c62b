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

// A discrete distribution over a list of n lights as one block of 2n + 1 doubles: the cdf over the list's
// order (n + 1 entries), then each entry's pmf (n, as doubles, which hold the floats exactly). Samplers with a
// table per voxel miss the cache on each table they read: the search, a zero weight's skip and the pmf then
// cost one miss, where a Distribution1D and a pmf read back through Light::index cost four in a row.
// Its sums and pmf are Distribution1D's, so a table draws what one built from a Distribution1D would.
namespace light_table {
inline size_t block_size(size_t n) { return 2 * n + 1; }
// Fills block (block_size(n) doubles) from n weights (NaN, inf or negative ones are never drawn).
void fill(const std::vector<float> &weights, double *block);
// The list index drawn by u, and its pmf.
size_t sample(const double *block, size_t n, float u, float &pmf);
inline float pmf(const double *block, size_t n, size_t i) { return float(block[n + 1 + i]); }
}  // namespace light_table

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

private:
    std::vector<double> block_;        // a light_table
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
