#include "neepp/light_selection/visibility_environment.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace neepp {

namespace {
// The axis of orientation bucket b (normal_bucket's classes: ±x, ±y, ±z).
Vec3 bucket_axis(uint32_t b) {
    Vec3 a(0.f);
    a[int(b / 2)] = b % 2 == 0 ? 1.f : -1.f;
    return a;
}
}  // namespace

VisibilityEnvironmentSampler::VisibilityEnvironmentSampler(const EnvironmentMapLight &env, const VoxelGrid &grid,
                                                           const VisibilityMap &map, VisibilityEnvironmentOptions options)
    : env_(env), map_(map), options_(options), keys_(grid, options.oriented), tables_(keys_.count()) {
    if (!(options_.epsilon > 0 && options_.epsilon <= 1))
        throw std::invalid_argument("the defensive fraction must be in (0, 1]: a direction with zero density would bias the image");
    if (!(options_.delta >= 0 && options_.delta <= 1)) throw std::invalid_argument("delta must be in [0, 1]");
    const int w = env.sampling_width(), h = env.sampling_height();
    const AliasTable &cells = env.sampling_cells();
    const uint32_t n = uint32_t(w) * uint32_t(h);
    groups_.resize(kGroups);
    cells_.resize(n);
    std::vector<uint32_t> local(n);
    std::vector<std::vector<float>> weights(kGroups);
    for (uint32_t c = 0; c < n; ++c) {
        // A cell belongs to the bin its centre points into; the density stays exact whatever the
        // assignment, since a direction's group is looked up the same way when its density is asked.
        const Vec2 centre((float(c % uint32_t(w)) + 0.5f) / float(w), (float(c / uint32_t(w)) + 0.5f) / float(h));
        const Vec3 d = env.uv_to_direction(centre);
        const uint32_t g = grid.cell_of_direction(d) - grid.voxel_count();
        cells_[c].group = g;
        const float p = cells.pmf(c);
        if (!(p > 0)) continue;  // never sampled by the map itself: never by a group either
        Group &group = groups_[g];
        local[c] = uint32_t(group.cells.size());
        group.cells.push_back(c);
        weights[g].push_back(p);
        group.mass += p;
        for (uint32_t b = 0; b < kNoOrientation; ++b)
            group.facing[b] += p * (0.1f + 0.9f * std::max(0.f, dot(d, bucket_axis(b))));
    }
    for (uint32_t g = 0; g < kGroups; ++g) {
        Group &group = groups_[g];
        if (weights[g].empty()) continue;
        group.table = AliasTable(weights[g]);
        for (const uint32_t c : group.cells) cells_[c].pmf = group.table.pmf(local[c]);
        for (uint32_t b = 0; b < kNoOrientation; ++b) group.facing[b] = float(group.facing[b] / group.mass);
        group.facing[kNoOrientation] = 1.f;
    }
}

std::unique_ptr<VisibilityEnvironmentSampler::GroupTable> VisibilityEnvironmentSampler::build(uint32_t key) const {
    const uint32_t voxel = keys_.voxel(key), bucket = keys_.oriented() ? keys_.bucket(key) : kNoOrientation;
    const uint32_t first_bin = keys_.grid().voxel_count();
    std::array<double, kGroups> w{};
    double total = 0, mass = 0;
    for (uint32_t g = 0; g < kGroups; ++g) {
        if (groups_[g].cells.empty()) continue;
        // sqrt(ν): a group whose shadow rays a fraction ν get through adds M_g²·ν / P(g) to the second
        // moment of the estimate, least for P(g) ∝ M_g·sqrt(ν). ν is the fraction the map has seen (a
        // prior would put every pair seen 16 times occluded at 1/18, and the many such groups would keep
        // most samples); never seen, or no map yet: visible, as far as anyone knows.
        float v = 1.f;
        if (map_.pair_count())
            if (const PairCounts c = map_.counts(voxel, first_bin + g); c.traced)
                v = std::sqrt(float(c.visible) / float(c.traced));
        w[g] = groups_[g].mass * groups_[g].facing[bucket] * std::max(v, options_.delta);
        total += w[g];
        mass += groups_[g].mass;
    }
    std::vector<float> p(kGroups, 0.f);
    for (uint32_t g = 0; g < kGroups; ++g)
        if (!groups_[g].cells.empty())
            p[g] = float((1.0 - options_.epsilon) * (total > 0 ? w[g] / total : groups_[g].mass / mass) +
                         options_.epsilon * groups_[g].mass / mass);
    return std::make_unique<GroupTable>(p);
}

const VisibilityEnvironmentSampler::GroupTable &VisibilityEnvironmentSampler::table(const LightSampleContext &ctx) const {
    return tables_.get(keys_.of(ctx), [this](uint32_t key) { return build(key); });
}

void VisibilityEnvironmentSampler::prefetch(const LightSampleContext &ctx, Vec2 u) const {
    // The group's choice reads a small table that stays in cache; what begin() then reads of the group's
    // cells (their alias bin and cell index, in tables as large as the map's own) is fetched ahead.
    uint64_t rest;
    const Group &group = groups_[table(ctx).sample_bits(AliasTable::bits_of(u), rest)];
    const uint32_t i = group.table.first_index(rest);
    group.table.prefetch_bits(rest);
    __builtin_prefetch(&group.cells[i]);
}

LightSampleStart VisibilityEnvironmentSampler::begin(const LightSampleContext &ctx, Vec2 u) const {
    float group_pmf, cell_pmf;
    uint64_t rest;
    const Group &group = groups_[table(ctx).sample_bits(AliasTable::bits_of(u), rest, &group_pmf)];
    Vec2 offset;
    const uint32_t cell = group.cells[group.table.sample_bits(rest, offset, &cell_pmf)];
    const int w = env_.sampling_width(), h = env_.sampling_height();
    LightSampleStart start{u};
    start.point = Vec2((float(cell % uint32_t(w)) + offset.x) / float(w), (float(cell / uint32_t(w)) + offset.y) / float(h));
    start.density = group_pmf * cell_pmf * float(w) * float(h);
    env_.prefetch_lookup(start.point);
    return start;
}

DirectionSample VisibilityEnvironmentSampler::finish(const LightSampleContext &ctx, const LightSampleStart &start,
                                                     Color &radiance) const {
    return env_.direction_from_uv(ctx.p, start.point, start.density, radiance);
}

float VisibilityEnvironmentSampler::pdf(const LightSampleContext &ctx, const DirectionSample &ds) const {
    const Vec2 uv = env_.direction_to_uv(ds.d);
    const CellInfo cell = cells_[env_.sampling_cell(uv)];
    if (!(cell.pmf > 0)) return 0.f;  // a cell the map never samples
    const int w = env_.sampling_width(), h = env_.sampling_height();
    return EnvironmentMapLight::solid_angle_density(uv, table(ctx).pmf(cell.group) * cell.pmf * float(w) * float(h));
}

std::vector<double> VisibilityEnvironmentSampler::group_probabilities(const LightSampleContext &ctx) const {
    const GroupTable &t = table(ctx);
    std::vector<double> p(kGroups);
    for (uint32_t g = 0; g < kGroups; ++g) p[g] = t.pmf(g);
    return p;
}

void VisibilityEnvironmentSampler::end_pass() {
    tables_.clear();
    ++passes_;
}

nlohmann::json VisibilityEnvironmentSampler::statistics() const {
    uint32_t used = 0;
    for (const Group &g : groups_) used += !g.cells.empty();
    return {{"epsilon", options_.epsilon}, {"delta", options_.delta}, {"oriented", options_.oriented},
            {"direction_groups", used}, {"tables_built", tables_.built()}, {"refreshes", passes_}};
}

}  // namespace neepp
