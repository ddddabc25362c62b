// Per-voxel light distributions for the spatial and visibility-aware light samplers: one discrete
// distribution over the scene's lights for every voxel of a grid, built the first time a shading point
// in that voxel asks (most voxels of a 16³ grid are empty space and never do).
// Thread safety as LazyVoxelArray: since a table depends only on (voxel, state frozen for the pass), the
// pmf a sample was drawn with is exactly the one pmf() later reports. clear() only between passes.
#pragma once
#include <functional>
#include <vector>
#include "neepp/light_selection/basic_light_samplers.h"
#include "neepp/light_selection/lazy_voxel_array.h"

namespace neepp {

class VoxelLightTables {
public:
    // Fills weights (one per light, in the order of `lights`, non-negative, at least one positive) for a voxel.
    using WeightFunction = std::function<void(uint32_t voxel, std::vector<float> &weights)>;

    VoxelLightTables(std::vector<const Light *> lights, uint32_t voxel_count, WeightFunction weights);

    SampledLight sample(uint32_t voxel, float u) const;
    float pmf(uint32_t voxel, const Light &light) const;

    // Drops every table (between passes), so they are rebuilt from the current state.
    void clear() { tables_.clear(); }
    uint64_t tables_built() const { return tables_.built(); }
    const std::vector<const Light *> &lights() const { return lights_; }

private:
    const double *table(uint32_t voxel) const;  // a light_table over lights_
    std::unique_ptr<double[]> build(uint32_t voxel) const;

    std::vector<const Light *> lights_;
    std::vector<int32_t> position_;  // by Light::index: its place in lights_, or -1
    WeightFunction weights_;
    LazyVoxelArray<double[]> tables_;
};

}  // namespace neepp
