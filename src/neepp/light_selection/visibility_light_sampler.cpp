#include "neepp/light_selection/visibility_light_sampler.h"

#include <stdexcept>

namespace neepp {

VisibilityLightSampler::VisibilityLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid,
                                               const VisibilityMap &map, const Vec3 &reference,
                                               VisibilitySelectionOptions options)
    : lights_(lights), grid_(grid), map_(map), options_(std::move(options)),
      tables_(lights, grid.voxel_count(), [this](uint32_t voxel, std::vector<float> &w) { weights(voxel, w); }) {
    if (map.cell_count() != grid.cell_count()) throw std::invalid_argument("visibility light sampler: map and grid disagree");
    if (!(options_.epsilon > 0 && options_.epsilon <= 1))
        throw std::invalid_argument("the defensive fraction must be in (0, 1]: a light with zero probability would bias the image");
    if (!(options_.delta >= 0 && options_.delta <= 1)) throw std::invalid_argument("delta must be in [0, 1]");
    coverage_ = light_coverage(grid, lights_, reference);
    double total = 0;
    for (const Light *l : lights_) total += std::max(0.f, luminance(l->power()));
    for (const Light *l : lights_)
        power_weights_.push_back(total > 0 ? float(std::max(0.f, luminance(l->power())) / total) : 1.f / float(lights_.size()));
    if (options_.base == "spatial") {
        SpatialEstimateOptions so = options_.spatial;
        spatial_ = std::make_unique<VoxelLightTables>(lights_, grid.voxel_count(),
            [this, so](uint32_t voxel, std::vector<float> &w) { spatial_light_weights(grid_, voxel, lights_, so, w); });
    } else if (options_.base != "power") {
        throw std::invalid_argument("visibility light sampler: base must be 'spatial' or 'power'");
    }
}

float VisibilityLightSampler::light_visibility(uint32_t voxel, size_t l) const {
    double v = 0;
    for (const CellWeight &cw : coverage_[l]) {
        const PairCounts c = map_.counts(voxel, cw.cell);
        const bool unknown = c.traced == 0 || cw.cell == voxel;
        v += double(cw.weight) * (unknown ? 1.0 : double(VisibilityMap::estimate(c)));
    }
    return float(v);
}

void VisibilityLightSampler::weights(uint32_t voxel, std::vector<float> &w) const {
    const size_t n = lights_.size();
    std::vector<float> base(n);
    for (size_t l = 0; l < n; ++l) base[l] = spatial_ ? spatial_->pmf_table(voxel)[lights_[l]->index] : power_weights_[l];
    double total = 0;
    for (size_t l = 0; l < n; ++l) {
        w[l] = base[l] * std::max(light_visibility(voxel, l), options_.delta);
        total += w[l];
    }
    for (size_t l = 0; l < n; ++l)
        w[l] = float((1.0 - options_.epsilon) * (total > 0 ? w[l] / total : base[l]) + options_.epsilon * base[l]);
}

void VisibilityLightSampler::end_pass() {
    // The map has merged the pass's shadow rays: rebuild lazily from it.
    tables_.clear();
    ++passes_;
}

nlohmann::json VisibilityLightSampler::statistics() const {
    uint64_t covered = 0;
    for (auto &c : coverage_) covered += c.size();
    return {{"base", options_.base},
            {"epsilon", options_.epsilon},
            {"delta", options_.delta},
            {"light_cells", covered},
            {"tables_built", tables_.tables_built()},  // over all passes
            {"refreshes", passes_},
            {"spatial_tables_built", spatial_ ? spatial_->tables_built() : 0}};
}

}  // namespace neepp
