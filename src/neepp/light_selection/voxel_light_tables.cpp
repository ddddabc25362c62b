#include "neepp/light_selection/voxel_light_tables.h"

#include <cmath>
#include <stdexcept>

namespace neepp {

VoxelLightTables::VoxelLightTables(std::vector<const Light *> lights, uint32_t voxel_count, WeightFunction weights)
    : lights_(std::move(lights)), weights_(std::move(weights)), tables_(voxel_count) {}

std::unique_ptr<LightDistribution> VoxelLightTables::build(uint32_t voxel) const {
    std::vector<float> w(lights_.size(), 0.f);
    weights_(voxel, w);
    double total = 0;
    for (float &x : w) {
        if (!(x >= 0) || !std::isfinite(x)) x = 0;  // NaN or negative: never a probability
        total += x;
    }
    if (!(total > 0)) throw std::logic_error("light table without a positive weight");
    return std::make_unique<LightDistribution>(lights_, w);
}

const LightDistribution &VoxelLightTables::table(uint32_t voxel) const {
    return tables_.get(voxel, [this](uint32_t v) { return build(v); });
}

SampledLight VoxelLightTables::sample(uint32_t voxel, float u) const {
    return lights_.empty() ? SampledLight{} : table(voxel).sample(lights_, u);
}

float VoxelLightTables::pmf(uint32_t voxel, const Light &light) const {
    return lights_.empty() ? 0.f : table(voxel).pmf(light);
}

}  // namespace neepp
