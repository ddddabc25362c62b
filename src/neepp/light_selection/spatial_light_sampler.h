// The "spatial" light sampler the paper compares against: per voxel of a regular grid, lights are chosen
// in proportion to an estimate of their unoccluded contribution to the voxel, i.e. the radiance they send
// to it integrated over solid angle, ∫ L_e dω, averaged over points of the voxel. It knows distance,
// size and facing, not occlusion. A defensive share of power sampling keeps every light with power
// reachable even where the estimate (a few light samples from a few points) saw nothing.
#pragma once
#include <memory>
#include "neepp/light_selection/voxel_light_tables.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

struct SpatialEstimateOptions {
    int points_per_voxel = 16;    // stratified points inside the voxel, one light sample each per light
    float power_fraction = 0.1f;  // defensive share of power sampling
};

// Fills one weight per light (in `lights` order) with the voxel's normalized spatial estimate mixed with
// power: (1 − f) · s_l / Σs + f · P_l / ΣP. Deterministic in (grid, voxel, lights).
void spatial_light_weights(const VoxelGrid &grid, uint32_t voxel, const std::vector<const Light *> &lights,
                           const SpatialEstimateOptions &options, std::vector<float> &weights);

class SpatialLightSampler final : public LightSampler {
public:
    SpatialLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid, SpatialEstimateOptions options = {});
    SampledLight sample(const LightSampleContext &ctx, float u) const override {
        return tables_.sample(grid_.voxel_of(ctx.p), u);
    }
    float pmf(const LightSampleContext &ctx, const Light &light) const override {
        return tables_.pmf(grid_.voxel_of(ctx.p), light);
    }
    std::string name() const override { return "spatial"; }
    nlohmann::json statistics() const override;

private:
    VoxelGrid grid_;
    VoxelLightTables tables_;
};

}  // namespace neepp
