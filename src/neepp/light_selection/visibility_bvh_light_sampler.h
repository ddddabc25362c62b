// The light BVH and NEE++'s visibility map combined: the BVH's descent with every node's importance
// multiplied by max(Ṽ(a, node), δ), where Ṽ(a, node) is the power-weighted mean visibility between the
// shading voxel a and the lights below the node (leaves: LightVisibility), mixed with the plain BVH:
//     p(l | x) = ε · p_bvh(l | x) + (1 − ε) · p_bvh·Ṽ(l | x).
// The plain share keeps every light the BVH can reach at a nonzero probability whatever the map says.
// Per-voxel node factors are built lazily from the map frozen for the pass and dropped after each pass.
// Environment lights are chosen apart, as in the BVH, without visibility.
#pragma once
#include "neepp/light_selection/bvh_light_sampler.h"
#include "neepp/light_selection/lazy_voxel_array.h"
#include "neepp/light_selection/light_coverage.h"

namespace neepp {

class VisibilityBVHLightSampler final : public LightSampler {
public:
    // grid and map must outlive the sampler (NEE++'s shadow-ray component owns and updates them).
    VisibilityBVHLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid, const VisibilityMap &map,
                              const Vec3 &reference, float epsilon = 0.1f, float delta = 0.01f);
    SampledLight sample(const LightSampleContext &ctx, float u) const override;
    float pmf(const LightSampleContext &ctx, const Light &light) const override;
    std::string name() const override { return "visibility-bvh"; }
    void end_pass() override { factors_.clear(); }
    nlohmann::json statistics() const override;

private:
    using Factors = std::vector<float>;
    const float *factors(uint32_t voxel) const;
    float mix(float p_plain, float p_visible) const { return epsilon_ * p_plain + (1 - epsilon_) * p_visible; }

    BVHLightSampler bvh_;
    const VoxelGrid &grid_;
    LightVisibility visibility_;
    float epsilon_, delta_;
    LazyVoxelArray<Factors> factors_;
};

}  // namespace neepp
