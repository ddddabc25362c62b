#include "neepp/light_selection/spatial_light_sampler.h"

#include <algorithm>

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
                           const std::vector<float> &power, const SpatialEstimateOptions &options,
                           std::vector<float> &weights) {
    const size_t n = lights.size();
    std::vector<double> estimate(n, 0.0);
    int x, y, z;
    grid.voxel_coords(voxel, x, y, z);
    const Vec3 size = grid.bounds().extent() / float(grid.resolution());
    const Vec3 lo = grid.bounds().lo + Vec3(float(x) * size.x, float(y) * size.y, float(z) * size.z);
    Vec3 axis(0.f);
    const bool oriented = bucket != kNoOrientation;
    if (oriented) axis[int(bucket / 2)] = bucket % 2 ? -1.f : 1.f;
    PCG32 rng(mix_bits(0x5ba71a1ULL ^ voxel), voxel);
    // Points on a jittered 1D sequence of the voxel's volume: stratification across points matters less
    // than keeping the estimate a pure function of the voxel.
    const int points = int(std::clamp<size_t>(size_t(options.light_samples_per_table) / std::max<size_t>(n, 1), 1,
                                              size_t(std::max(options.points_per_voxel, 1))));
    for (int k = 0; k < points; ++k) {
        const Vec3 p = lo + Vec3(rng.next_float() * size.x, rng.next_float() * size.y, rng.next_float() * size.z);
        for (size_t l = 0; l < n; ++l) {
            Color Le;
            DirectionSample ds = lights[l]->sample_direction(p, rng.next_2d(), Le);
            if (!(ds.pdf > 0)) continue;
            double c = double(luminance(Le)) / double(ds.pdf);  // one-sample estimate of ∫ L_e dω
            if (oriented) c *= 0.1 + 0.9 * std::max(0.f, dot(axis, ds.d));
            if (c > 0 && std::isfinite(c)) estimate[l] += c;
        }
    }
    double total = 0;
    for (double e : estimate) total += e;
    for (size_t l = 0; l < n; ++l) {
        const double spatial = total > 0 ? estimate[l] / total : power[l];
        weights[l] = float((1.0 - options.power_fraction) * spatial + options.power_fraction * power[l]);
    }
}

SpatialLightSampler::SpatialLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid,
                                         SpatialEstimateOptions options)
    : options_(options), keys_(grid, options.oriented), power_(power_fractions(lights)),
      tables_(lights, keys_.count(), [this](uint32_t key, std::vector<float> &w) {
          spatial_light_weights(keys_.grid(), keys_.voxel(key), keys_.bucket(key), tables_.lights(), power_, options_, w);
      }) {}

nlohmann::json SpatialLightSampler::statistics() const {
    return {{"voxels", keys_.grid().resolution()}, {"oriented", keys_.oriented()}, {"tables_built", tables_.tables_built()}};
}

}  // namespace neepp
