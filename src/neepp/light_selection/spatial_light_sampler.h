// The "spatial" light sampler the paper compares against: per voxel of a regular grid, lights are chosen
// in proportion to an estimate of their unoccluded contribution to the voxel, i.e. the radiance they send
// to it integrated over solid angle, ∫ L_e dω, averaged over points of the voxel. It knows distance,
// size and facing, not occlusion. A defensive share of power sampling keeps every light with power
// reachable even where the estimate (a few light samples from a few points) saw nothing.
#pragma once
#include <memory>
#include "neepp/light_selection/voxel_light_tables.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

struct SpatialEstimateOptions {
    int points_per_voxel = 16;    // stratified points inside the voxel, one light sample each per light
    // At most about this many light samples per table: with thousands of lights the points are fewer (down
    // to one), or building a table would cost points × lights samples (with 10^4 lights, 160 000 per
    // table; tables were then 75 % of a render). From 256 lights down, every table has all its points.
    int light_samples_per_table = 4096;
    float power_fraction = 0.1f;  // defensive share of power sampling
    bool oriented = false;        // tables per (voxel, receiver orientation bucket), see normal_bucket()
};

// Receiver orientation classes, for tables that also know which way the shading point faces: the
// dominant axis of its normal (face-forwarded toward the side light is gathered on), 6 classes, plus one
// for "no normal". A class is a pure function of the normal, so the pmf stays exactly reproducible.
constexpr uint32_t kNormalBuckets = 7;
constexpr uint32_t kNoOrientation = 6;
uint32_t normal_bucket(const Vec3 &n);

// Which per-cell table a shading point reads: its voxel or, with orientation, (voxel, normal bucket).
class TableKeys {
public:
    TableKeys(const VoxelGrid &grid, bool oriented) : grid_(grid), oriented_(oriented) {}
    uint32_t count() const { return grid_.voxel_count() * (oriented_ ? kNormalBuckets : 1); }
    uint32_t of(const LightSampleContext &ctx) const {
        const uint32_t v = grid_.voxel_of(ctx.p);
        return oriented_ ? v * kNormalBuckets + normal_bucket(ctx.n) : v;
    }
    uint32_t voxel(uint32_t key) const { return oriented_ ? key / kNormalBuckets : key; }
    uint32_t bucket(uint32_t key) const { return oriented_ ? key % kNormalBuckets : kNoOrientation; }
    bool oriented() const { return oriented_; }
    const VoxelGrid &grid() const { return grid_; }

private:
    VoxelGrid grid_;
    bool oriented_;
};

// Fills one weight per light (in `lights` order) with the voxel's normalized spatial estimate mixed with
// power (power: power_fractions(lights)): (1 − f) · s_l / Σs + f · P_l. Deterministic in (grid, voxel,
// bucket, lights). With an orientation bucket each light sample counts (0.1 + 0.9·max(0, cos)) times,
// cos taken with the bucket's axis: lights behind a receiver weigh less (never zero: the bucket is only
// a dominant axis).
void spatial_light_weights(const VoxelGrid &grid, uint32_t voxel, uint32_t bucket, const std::vector<const Light *> &lights,
                           const std::vector<float> &power, const SpatialEstimateOptions &options,
                           std::vector<float> &weights);

class SpatialLightSampler final : public LightSampler {
public:
    // Unoriented: the paper's baseline ("spatial"); oriented: ours ("spatial-oriented"), to tell apart
    // what orientation and what visibility buy in the visibility sampler, which builds on this one.
    SpatialLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid, SpatialEstimateOptions options = {});
    SampledLight sample(const LightSampleContext &ctx, float u) const override { return tables_.sample(keys_.of(ctx), u); }
    float pmf(const LightSampleContext &ctx, const Light &light) const override { return tables_.pmf(keys_.of(ctx), light); }
    std::string name() const override { return keys_.oriented() ? "spatial-oriented" : "spatial"; }
    nlohmann::json statistics() const override;

    // For samplers built on this one: the table a shading point reads, and a light's pmf in that table.
    const TableKeys &keys() const { return keys_; }
    float table_pmf(uint32_t key, const Light &light) const { return tables_.pmf(key, light); }

private:
    SpatialEstimateOptions options_;
    TableKeys keys_;
    std::vector<float> power_;  // power_fractions of the lights
    VoxelLightTables tables_;
};

}  // namespace neepp
