#include "neepp/light_selection/visibility_light_sampler.h"

#include <stdexcept>

namespace neepp {

VisibilityLightSampler::VisibilityLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid,
                                               const VisibilityMap &map, const Vec3 &reference,
                                               VisibilitySelectionOptions options)
    : lights_(lights), grid_(grid), options_(std::move(options)),
      oriented_(options_.oriented && options_.base == "spatial"), visibility_(grid, map, lights, reference),
      tables_(lights, grid.voxel_count() * (oriented_ ? kNormalBuckets : 1),
              [this](uint32_t key, std::vector<float> &w) { weights(key, w); }) {
    if (!(options_.epsilon > 0 && options_.epsilon <= 1))
        throw std::invalid_argument("the defensive fraction must be in (0, 1]: a light with zero probability would bias the image");
    if (!(options_.delta >= 0 && options_.delta <= 1)) throw std::invalid_argument("delta must be in [0, 1]");
    double total = 0;
    for (const Light *l : lights_) total += std::max(0.f, luminance(l->power()));
    for (const Light *l : lights_)
        power_weights_.push_back(total > 0 ? float(std::max(0.f, luminance(l->power())) / total) : 1.f / float(lights_.size()));
    if (options_.base == "spatial") {
        SpatialEstimateOptions so = options_.spatial;
        const uint32_t buckets = oriented_ ? kNormalBuckets : 1;
        spatial_ = std::make_unique<VoxelLightTables>(lights_, grid.voxel_count() * buckets,
            [this, so, buckets](uint32_t key, std::vector<float> &w) {
                spatial_light_weights(grid_, key / buckets, buckets > 1 ? key % buckets : 6, lights_, so, w);
            });
    } else if (options_.base != "power") {
        throw std::invalid_argument("visibility light sampler: base must be 'spatial' or 'power'");
    }
}

void VisibilityLightSampler::weights(uint32_t key, std::vector<float> &w) const {
    const size_t n = lights_.size();
    const uint32_t voxel = oriented_ ? key / kNormalBuckets : key;
    std::vector<float> base(n);
    for (size_t l = 0; l < n; ++l) base[l] = spatial_ ? spatial_->pmf_table(key)[lights_[l]->index] : power_weights_[l];
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
            {"oriented", oriented_},
            {"epsilon", options_.epsilon},
            {"delta", options_.delta},
            {"light_cells", visibility_.covered_cells()},
            {"tables_built", tables_.tables_built()},  // over all passes
            {"refreshes", passes_},
            {"spatial_tables_built", spatial_ ? spatial_->tables_built() : 0}};
}

}  // namespace neepp
