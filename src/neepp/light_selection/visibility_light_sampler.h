// NEE++'s visibility-aware light selection (NEEPP.md §3): for a shading point in voxel a, light l is
// chosen with
//     p(l | a) = (1 − ε) · w_l(a) · max(Ṽ(a, l), δ) / Σ_k w_k(a) · max(Ṽ(a, k), δ)  +  ε · w_l(a)
// where w(a) is a base distribution (the spatial estimate, or power) and Ṽ(a, l) the visibility map's
// estimate between a and the cells light l covers, weighted by how much of the light each holds. Pairs
// the map has never seen, and a's own voxel, count as visible (the map cannot tell). The defensive ε · w
// keeps every light the base sampler can pick at a nonzero probability, so a map that is wrong costs
// variance, never bias. Tables are built lazily per visited voxel from the map frozen for the pass and
// dropped after each pass, when the map has learned from the pass's shadow rays.
#pragma once
#include "neepp/light_selection/light_coverage.h"
#include "neepp/light_selection/spatial_light_sampler.h"
#include "neepp/visibility/visibility_map.h"

namespace neepp {

struct VisibilitySelectionOptions {
    std::string base = "spatial";  // w: "spatial" or "power"
    float epsilon = 0.1f;          // defensive share of the base distribution
    float delta = 0.01f;           // floor of Ṽ: a light the map calls occluded keeps some weight
    SpatialEstimateOptions spatial;
    // Tables per (voxel, receiver orientation) rather than per voxel (spatial base only): lights behind
    // the shading point's surface weigh less. Ours, beyond the paper.
    bool oriented = true;
};

class VisibilityLightSampler final : public LightSampler {
public:
    // grid and map must outlive the sampler (they belong to NEE++'s shadow-ray component, which keeps
    // learning into the map between passes).
    VisibilityLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid, const VisibilityMap &map,
                           const Vec3 &reference, VisibilitySelectionOptions options = {});
    SampledLight sample(const LightSampleContext &ctx, float u) const override { return tables_.sample(keys_.of(ctx), u); }
    float pmf(const LightSampleContext &ctx, const Light &light) const override { return tables_.pmf(keys_.of(ctx), light); }
    std::string name() const override { return "visibility"; }
    void end_pass() override;
    nlohmann::json statistics() const override;

private:
    void weights(uint32_t key, std::vector<float> &w) const;

    std::vector<const Light *> lights_;
    VisibilitySelectionOptions options_;
    LightVisibility visibility_;
    std::vector<float> power_;                       // power_fractions, the base w when options_.base == "power"
    std::unique_ptr<SpatialLightSampler> spatial_;   // the base w when options_.base == "spatial"; never rebuilt
    TableKeys keys_;                                 // the base's keys (per voxel for power)
    VoxelLightTables tables_;
    uint64_t passes_ = 0;
};

}  // namespace neepp
