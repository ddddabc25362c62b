// NEE++ inside an environment map: its directions sampled per shading voxel in proportion to radiance
// and to what the visibility map has seen of them. The map's sampling cells are grouped by the grid's
// direction bin they point into, and a shading point in voxel a, facing orientation bucket o, picks
// group g with probability
//     P(g | a, o) = (1 − ε) · w_g / Σ_k w_k  +  ε · M_g,    w_g = M_g · F_g(o) · max(sqrt(ν(a, g)), δ)
// (M_g: the group's share of the map's own sampling density; F_g(o): how much of it faces the receiver;
// ν(a, g): the fraction of the pair's traced rays that got through, 1 for pairs never traced), then a
// cell of the group in proportion to the map's own density. A direction's density is
// therefore the map's own times P(g | a) / M_g: exact, so MIS against BSDF sampling stays correct, and
// positive wherever the map's own is (ε > 0), so a wrong visibility map costs variance, never bias.
// What it is for: sky seen through windows, where from inside a room most of the sky's radiance comes
// from directions the walls block, and plain importance sampling spends its shadow rays on them
// (Bitterli et al. 2015's portal-masked environment sampling, with the map in place of the portals).
// Tables per voxel are built lazily from the map frozen for the pass and dropped by end_pass().
#pragma once
#include <array>
#include <vector>
#include <nlohmann/json.hpp>
#include "neepp/light_selection/lazy_voxel_array.h"
#include "neepp/light_selection/spatial_light_sampler.h"
#include "neepp/light_selection/within_light_sampling.h"
#include "neepp/lights/environment_light.h"
#include "neepp/visibility/visibility_map.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

struct VisibilityEnvironmentOptions {
    float epsilon = 0.1f;  // defensive share of the map's own density
    float delta = 0.01f;   // floor of the visibility term: a group the map calls occluded keeps some weight
    // Tables per (voxel, receiver orientation) rather than per voxel: directions behind the shading
    // point's surface weigh 0.1 + 0.9 max(0, cos) of what they would (never zero: the orientation bucket
    // is only the normal's dominant axis, and transmissive surfaces gather from behind).
    bool oriented = true;
};

class VisibilityEnvironmentSampler final : public ContextLightSampler {
public:
    // env, grid and map must outlive this sampler (the map keeps learning between passes).
    VisibilityEnvironmentSampler(const EnvironmentMapLight &env, const VoxelGrid &grid, const VisibilityMap &map,
                                 VisibilityEnvironmentOptions options = {});
    void prefetch(const LightSampleContext &ctx, Vec2 u) const override;
    LightSampleStart begin(const LightSampleContext &ctx, Vec2 u) const override;
    DirectionSample finish(const LightSampleContext &ctx, const LightSampleStart &start, Color &radiance) const override;
    float pdf(const LightSampleContext &ctx, const DirectionSample &ds) const override;
    void end_pass() override;  // the map has learned: rebuild the tables from it, lazily
    nlohmann::json statistics() const override;

    // P(g | table) for every group (tests and tools), and the group of a map point.
    std::vector<double> group_probabilities(const LightSampleContext &ctx) const;
    uint32_t group_of(Vec2 uv) const { return cells_[env_.sampling_cell(uv)].group; }
    static constexpr uint32_t kGroups = VoxelGrid::kDirectionBins;

private:
    // One table's choice among the groups (an alias table: one cache line read per choice, and what is
    // left of u's bits after it goes on to the choice of a cell).
    using GroupTable = AliasTable;
    struct Group {
        std::vector<uint32_t> cells;  // the map's sampling cells in this group
        AliasTable table;             // over them, ∝ the map's own density
        double mass = 0;              // M_g
        std::array<float, kNormalBuckets> facing{};  // its mass-weighted 0.1 + 0.9 max(0, cos) per orientation bucket
    };
    std::unique_ptr<GroupTable> build(uint32_t key) const;
    const GroupTable &table(const LightSampleContext &ctx) const;

    const EnvironmentMapLight &env_;
    const VisibilityMap &map_;
    VisibilityEnvironmentOptions options_;
    TableKeys keys_;
    std::vector<Group> groups_;
    // Per sampling cell of the map, what its density needs, in one read: its group, and its probability
    // within the group (0 for a cell the map never samples), exactly as its group's table reports it.
    struct CellInfo {
        float pmf = 0;
        uint32_t group = 0;
    };
    std::vector<CellInfo> cells_;
    LazyVoxelArray<GroupTable> tables_;
    uint64_t passes_ = 0;
};

}  // namespace neepp
