#include "neepp/light_selection/spatial_light_sampler.h"

#include "neepp/sampling/rng.h"

namespace neepp {

void spatial_light_weights(const VoxelGrid &grid, uint32_t voxel, const std::vector<const Light *> &lights,
                           const SpatialEstimateOptions &options, std::vector<float> &weights) {
    const size_t n = lights.size();
    std::vector<double> estimate(n, 0.0);
    int x, y, z;
    grid.voxel_coords(voxel, x, y, z);
    const Vec3 size = grid.bounds().extent() / float(grid.resolution());
    const Vec3 lo = grid.bounds().lo + Vec3(float(x) * size.x, float(y) * size.y, float(z) * size.z);
    PCG32 rng(mix_bits(0x5ba71a1ULL ^ voxel), voxel);
    // Points on a jittered 1D sequence of the voxel's volume: stratification across points matters less
    // than keeping the estimate a pure function of the voxel.
    for (int k = 0; k < options.points_per_voxel; ++k) {
        const Vec3 p = lo + Vec3(rng.next_float() * size.x, rng.next_float() * size.y, rng.next_float() * size.z);
        for (size_t l = 0; l < n; ++l) {
            Color Le;
            DirectionSample ds = lights[l]->sample_direction(p, rng.next_2d(), Le);
            if (!(ds.pdf > 0)) continue;
            const double c = double(luminance(Le)) / double(ds.pdf);  // one-sample estimate of ∫ L_e dω
            if (c > 0 && std::isfinite(c)) estimate[l] += c;
        }
    }
    double total = 0, power_total = 0;
    for (size_t l = 0; l < n; ++l) {
        total += estimate[l];
        power_total += std::max(0.f, luminance(lights[l]->power()));
    }
    for (size_t l = 0; l < n; ++l) {
        const double power = std::max(0.f, luminance(lights[l]->power()));
        // With no power anywhere (black emitters) fall back to uniform, as the power sampler does.
        const double defensive = power_total > 0 ? power / power_total : 1.0 / double(n);
        const double spatial = total > 0 ? estimate[l] / total : defensive;
        weights[l] = float((1.0 - options.power_fraction) * spatial + options.power_fraction * defensive);
    }
}

SpatialLightSampler::SpatialLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid,
                                         SpatialEstimateOptions options)
    : grid_(grid),
      tables_(lights, grid.voxel_count(), [lights, grid, options](uint32_t voxel, std::vector<float> &w) {
          spatial_light_weights(grid, voxel, lights, options, w);
      }) {}

nlohmann::json SpatialLightSampler::statistics() const {
    return {{"voxels", grid_.resolution()}, {"tables_built", tables_.tables_built()}};
}

}  // namespace neepp
