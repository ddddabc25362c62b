#include "neepp/light_selection/voxel_light_tables.h"

#include <cmath>
#include <stdexcept>

namespace neepp {

VoxelLightTables::VoxelLightTables(std::vector<const Light *> lights, uint32_t voxel_count, WeightFunction weights)
    : lights_(std::move(lights)), weights_(std::move(weights)), tables_(voxel_count) {
    for (const Light *l : lights_) max_index_ = std::max(max_index_, l->index);
}

std::unique_ptr<VoxelLightTables::Table> VoxelLightTables::build(uint32_t voxel) const {
    std::vector<float> w(lights_.size(), 0.f);
    weights_(voxel, w);
    double total = 0;
    for (float &x : w) {
        if (!(x >= 0) || !std::isfinite(x)) x = 0;  // NaN or negative: never a probability
        total += x;
    }
    if (!(total > 0)) throw std::logic_error("light table without a positive weight");
    auto t = std::make_unique<Table>();
    t->distribution = Distribution1D(w);
    t->pmf_by_index.assign(lights_.empty() ? 0 : max_index_ + 1, 0.f);
    for (size_t i = 0; i < lights_.size(); ++i) t->pmf_by_index[lights_[i]->index] = t->distribution.pmf(uint32_t(i));
    return t;
}

const VoxelLightTables::Table &VoxelLightTables::table(uint32_t voxel) const {
    return tables_.get(voxel, [this](uint32_t v) { return build(v); });
}

SampledLight VoxelLightTables::sample(uint32_t voxel, float u) const {
    if (lights_.empty()) return {};
    const Table &t = table(voxel);
    uint32_t i = t.distribution.sample_discrete(u);
    return {lights_[i], t.pmf_by_index[lights_[i]->index]};
}

float VoxelLightTables::pmf(uint32_t voxel, const Light &light) const {
    if (lights_.empty()) return 0.f;
    const Table &t = table(voxel);
    return light.index < t.pmf_by_index.size() ? t.pmf_by_index[light.index] : 0.f;
}

}  // namespace neepp
