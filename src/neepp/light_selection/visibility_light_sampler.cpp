#include "neepp/light_selection/visibility_light_sampler.h"

#include <stdexcept>

namespace neepp {

namespace {
std::unique_ptr<SpatialLightSampler> make_base(const std::vector<const Light *> &lights, const VoxelGrid &grid,
                                               const VisibilitySelectionOptions &options) {
    if (options.base == "power") return nullptr;
    if (options.base != "spatial") throw std::invalid_argument("visibility light sampler: base must be 'spatial' or 'power'");
    SpatialEstimateOptions so = options.spatial;
    so.oriented = options.oriented;
    return std::make_unique<SpatialLightSampler>(lights, grid, so);
}
}  // namespace

VisibilityLightSampler::VisibilityLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid,
                                               const VisibilityMap &map, const Vec3 &reference,
                                               VisibilitySelectionOptions options)
    : lights_(lights), options_(std::move(options)), visibility_(grid, map, lights, reference),
      power_(power_fractions(lights)), spatial_(make_base(lights, grid, options_)),
      keys_(spatial_ ? spatial_->keys() : TableKeys(grid, false)),
      tables_(lights, keys_.count(), [this](uint32_t key, std::vector<float> &w) { weights(key, w); }) {
    if (!(options_.epsilon > 0 && options_.epsilon <= 1))
        throw std::invalid_argument("the defensive fraction must be in (0, 1]: a light with zero probability would bias the image");
    if (!(options_.delta >= 0 && options_.delta <= 1)) throw std::invalid_argument("delta must be in [0, 1]");
}

void VisibilityLightSampler::weights(uint32_t key, std::vector<float> &w) const {
    const size_t n = lights_.size();
    const uint32_t voxel = keys_.voxel(key);
    std::vector<float> base(n);
    for (size_t l = 0; l < n; ++l) base[l] = spatial_ ? spatial_->table_pmf(key, *lights_[l]) : power_[l];
    double total = 0;
    for (size_t l = 0; l < n; ++l) {
        w[l] = base[l] * std::max(visibility_(voxel, *lights_[l]), options_.delta);
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
    return {{"base", options_.base},
            {"oriented", keys_.oriented()},
            {"epsilon", options_.epsilon},
            {"delta", options_.delta},
            {"light_cells", visibility_.covered_cells()},
            {"tables_built", tables_.tables_built()},  // over all passes
            {"refreshes", passes_},
            {"spatial", spatial_ ? spatial_->statistics() : nlohmann::json()}};
}

}  // namespace neepp
