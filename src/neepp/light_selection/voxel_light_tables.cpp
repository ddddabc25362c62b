#include "neepp/light_selection/voxel_light_tables.h"

#include <cmath>
#include <stdexcept>

namespace neepp {

VoxelLightTables::VoxelLightTables(std::vector<const Light *> lights, uint32_t voxel_count, WeightFunction weights)
    : lights_(std::move(lights)), voxel_count_(voxel_count), weights_(std::move(weights)),
      tables_(new std::atomic<Table *>[voxel_count]) {
    for (const Light *l : lights_) max_index_ = std::max(max_index_, l->index);
    for (uint32_t v = 0; v < voxel_count_; ++v) tables_[v].store(nullptr, std::memory_order_relaxed);
}

VoxelLightTables::~VoxelLightTables() { clear(); }

void VoxelLightTables::clear() {
    for (uint32_t v = 0; v < voxel_count_; ++v) delete tables_[v].exchange(nullptr);
}

uint64_t VoxelLightTables::tables_resident() const {
    uint64_t n = 0;
    for (uint32_t v = 0; v < voxel_count_; ++v) n += tables_[v].load(std::memory_order_relaxed) != nullptr;
    return n;
}

const VoxelLightTables::Table &VoxelLightTables::table(uint32_t voxel) const {
    if (Table *t = tables_[voxel].load(std::memory_order_acquire)) return *t;
    std::vector<float> w(lights_.size(), 0.f);
    weights_(voxel, w);
    double total = 0;
    for (float &x : w) {
        if (!(x >= 0) || !std::isfinite(x)) x = 0;  // NaN or negative: never a probability
        total += x;
    }
    if (!(total > 0)) throw std::logic_error("light table without a positive weight");
    auto fresh = std::make_unique<Table>();
    fresh->distribution = Distribution1D(w);
    fresh->pmf_by_index.assign(lights_.empty() ? 0 : max_index_ + 1, 0.f);
    for (size_t i = 0; i < lights_.size(); ++i) fresh->pmf_by_index[lights_[i]->index] = fresh->distribution.pmf(uint32_t(i));
    Table *expected = nullptr;
    if (tables_[voxel].compare_exchange_strong(expected, fresh.get(), std::memory_order_acq_rel)) {
        built_.fetch_add(1, std::memory_order_relaxed);
        return *fresh.release();
    }
    return *expected;  // another thread built the same table first
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
