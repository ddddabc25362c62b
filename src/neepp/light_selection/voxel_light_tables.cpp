#include "neepp/light_selection/voxel_light_tables.h"

#include <cmath>
#include <stdexcept>

namespace neepp {

VoxelLightTables::VoxelLightTables(std::vector<const Light *> lights, uint32_t voxel_count, WeightFunction weights)
    : lights_(std::move(lights)), weights_(std::move(weights)), tables_(voxel_count) {
    for (size_t i = 0; i < lights_.size(); ++i) {
        if (position_.size() <= lights_[i]->index) position_.resize(lights_[i]->index + 1, -1);
        position_[lights_[i]->index] = int32_t(i);
    }
}

std::unique_ptr<double[]> VoxelLightTables::build(uint32_t voxel) const {
    std::vector<float> w(lights_.size(), 0.f);
    weights_(voxel, w);
    double total = 0;
    for (float x : w)
        if (x >= 0 && std::isfinite(x)) total += x;  // NaN or negative: never a probability
    if (!(total > 0)) throw std::logic_error("light table without a positive weight");
    std::unique_ptr<double[]> block(new double[light_table::block_size(w.size())]);
    light_table::fill(w, block.get());
    return block;
}

const double *VoxelLightTables::table(uint32_t voxel) const {
    return tables_.get(voxel, [this](uint32_t v) { return build(v); });
}

SampledLight VoxelLightTables::sample(uint32_t voxel, float u) const {
    if (lights_.empty()) return {};
    float pmf;
    const size_t i = light_table::sample(table(voxel), lights_.size(), u, pmf);
    return {lights_[i], pmf};
}

float VoxelLightTables::pmf(uint32_t voxel, const Light &light) const {
    if (light.index >= position_.size() || position_[light.index] < 0) return 0.f;
    return light_table::pmf(table(voxel), lights_.size(), size_t(position_[light.index]));
}

}  // namespace neepp
