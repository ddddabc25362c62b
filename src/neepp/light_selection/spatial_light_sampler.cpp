#include "neepp/light_selection/spatial_light_sampler.h"

#include "neepp/sampling/rng.h"

namespace neepp {

uint32_t normal_bucket(const Vec3 &n) {
    const float ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
    if (!(ax > 0 || ay > 0 || az > 0)) return 6;
    if (ax >= ay && ax >= az) return n.x > 0 ? 0 : 1;
    if (ay >= az) return n.y > 0 ? 2 : 3;
    return n.z > 0 ? 4 : 5;
}

void spatial_light_weights(const VoxelGrid &grid, uint32_t voxel, uint32_t bucket, const std::vector<const Light *> &lights,
                           const SpatialEstimateOptions &options, std::vector<float> &weights) {
    const size_t n = lights.size();
    std::vector<double> estimate(n, 0.0);
    int x, y, z;
    grid.voxel_coords(voxel, x, y, z);
    const Vec3 size = grid.bounds().extent() / float(grid.resolution());
    const Vec3 lo = grid.bounds().lo + Vec3(float(x) * size.x, float(y) * size.y, float(z) * size.z);
    Vec3 axis(0.f);
    if (bucket < 6) axis[int(bucket / 2)] = bucket % 2 ? -1.f : 1.f;
    PCG32 rng(mix_bits(0x5ba71a1ULL ^ voxel), voxel);
    // Points on a jittered 1D sequence of the voxel's volume: stratification across points matters less
    // than keeping the estimate a pure function of the voxel.
    for (int k = 0; k < options.points_per_voxel; ++k) {
        const Vec3 p = lo + Vec3(rng.next_float() * size.x, rng.next_float() * size.y, rng.next_float() * size.z);
        for (size_t l = 0; l < n; ++l) {
            Color Le;
            DirectionSample ds = lights[l]->sample_direction(p, rng.next_2d(), Le);
            if (!(ds.pdf > 0)) continue;
            double c = double(luminance(Le)) / double(ds.pdf);  // one-sample estimate of ∫ L_e dω
            if (bucket < 6) c *= 0.1 + 0.9 * std::max(0.f, dot(axis, ds.d));
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
    : grid_(grid), oriented_(options.oriented),
      tables_(lights, grid.voxel_count() * (options.oriented ? kNormalBuckets : 1),
              [lights, grid, options](uint32_t key, std::vector<float> &w) {
                  if (options.oriented) spatial_light_weights(grid, key / kNormalBuckets, key % kNormalBuckets, lights, options, w);
                  else spatial_light_weights(grid, key, 6, lights, options, w);
              }) {}

nlohmann::json SpatialLightSampler::statistics() const {
    return {{"voxels", grid_.resolution()}, {"oriented", oriented_}, {"tables_built", tables_.tables_built()}};
}

}  // namespace neepp
