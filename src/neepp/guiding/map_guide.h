// The visibility map's guide (guiding=map; ours, issue 44). The NEE++ grid already names every place a
// path can go: its voxels, and for what leaves the scene, its direction bins. At a shading point in voxel
// i the guide picks a target cell j with probability p(j | i), then a direction toward a uniform point of
// j's box (a voxel) or a direction in j's cube-map patch (a bin). No per-cell tree: one distribution over
// cells per shading voxel, and its density at a direction is a walk along the ray through the grid.
//
// p(j | i) ∝ the flux arriving at voxel i from cell j, learned from the paths: each guided vertex's record
// is the radiance its direction brought back over the direction's density, filed under (i, the cell where
// the direction's ray ended). A voxel target is sampled in the box of the end points recorded in it (at
// least a twentieth of the voxel thick), not in the whole voxel: a floor's voxel is then a slab on the
// floor, and its directions go to the floor rather than past it. Where voxel i has few records, the map supplies a prior: Ṽ(i, j) × the mean
// radiance that cell j sent along every recorded ray that ended there × j's solid angle from i, blended
// with the learned flux as k pseudo-records would be. The learned sums grow over every pass (each record
// is an unbiased estimate, whatever guide drew it), so the guide sharpens as the render goes on.
//
// Records arrive from every render thread. Each pass's are summed as fixed-point integers per (i, j) under
// a lock per voxel stripe (integer sums do not depend on the order of additions), and folded into the
// totals between passes, single-threaded: a pass's guide is a function of the records, not of the
// threads' timing, so images are the same to the bit for a seed and thread count.
#pragma once
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>
#include <nlohmann/json.hpp>
#include "neepp/math/bbox.h"
#include "neepp/math/vec.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

class VisibilityMap;

struct MapGuideOptions {
    double prior_records = 64;          // k: the map's prior weighs as this many of a voxel's own records
    size_t max_table_bytes = 512u << 20;  // dense tables at most (the most-recorded voxels get one)
};

class MapGuide {
public:
    // One shading voxel's distribution over target cells.
    struct Table {
        std::vector<float> pmf;      // per cell of the grid (cell_count), summing to 1
        std::vector<uint32_t> cells;  // the cells with pmf > 0, ascending
        std::vector<float> cdf;       // running sums of their pmf (the last is 1)
    };

    MapGuide(const VoxelGrid &grid, MapGuideOptions options = {});

    const VoxelGrid &grid() const { return grid_; }
    // The table the coming pass samples at the voxel of p; null where the voxel has none (no guide there).
    const Table *table_at(const Vec3 &p) const {
        const int32_t t = table_of_voxel_.empty() ? -1 : table_of_voxel_[grid_.voxel_of(p)];
        return t < 0 ? nullptr : &tables_[size_t(t)];
    }
    // Solid-angle density of unit direction d from p under table t, and a direction drawn with it
    // (u_cell picks the cell, (u1, u2) the point in it; a zero vector where the point falls on p).
    float pdf(const Table &t, const Vec3 &p, const Vec3 &d) const;
    Vec3 sample(const Table &t, const Vec3 &p, float u_cell, float u1, Vec2 u2) const;

    // The target cell of a ray from a shading point in direction d: the voxel of its end point, or, for a
    // ray that left the scene, d's direction bin.
    uint32_t target_of(const Vec3 &end, const Vec3 &d, bool escaped) const {
        return grid_.cell_of_end(end, d, escaped);
    }
    static constexpr uint32_t kNoTarget = 0xffffffffu;
    // A record from a vertex at p whose direction's ray ended at `end` in cell `target` (kNoTarget:
    // unknown, e.g. the path stopped; it still counts as one of the voxel's samples; `end` is read for voxel
    // targets only): `flux` = the radiance that arrived over the direction's density, `radiance` = what
    // arrived. Thread-safe; sums (and the end points' bounds) are order-independent.
    void record(const Vec3 &p, uint32_t target, double flux, double radiance, const Vec3 &end);
    // Where the coming pass samples voxel target j (a box within the voxel; the voxel's own box before any
    // end point was recorded in it).
    const BBox &target_box(uint32_t voxel) const { return boxes_[voxel]; }

    // Between passes, single-threaded: the pass's records join the totals and the tables are rebuilt,
    // the prior reading `map` (null: no prior, the records alone).
    void update(const VisibilityMap *map);

    size_t table_count() const { return tables_.size(); }
    uint64_t records() const { return records_; }  // in all passes so far
    nlohmann::json statistics() const;

    // Exact bytes of the learned totals, between passes (tables are rebuilt from them by update()).
    std::string save() const;
    // Replaces the totals (throws std::runtime_error if malformed or for another grid); call update().
    void load(std::string_view bytes);
    // Distributed rendering: renders that each started from `base` and learned, as one that had recorded
    // what all of them recorded (base + the sum of what each added). Deterministic, in the order given.
    static std::string merge(std::string_view base, std::span<const std::string> learned);

private:
    struct Acc {  // one pass's fixed-point sums of a (voxel, target) pair
        uint64_t flux = 0, radiance = 0, count = 0;
    };
    struct Total {
        double flux = 0, radiance = 0;
        uint64_t count = 0;
    };
    struct Voxel {
        std::unordered_map<uint32_t, Acc> pass;     // this pass
        uint64_t pass_samples = 0;
        std::unordered_map<uint32_t, Total> total;  // all passes so far
        uint64_t samples = 0;                       // N_i: directions drawn from the voxel, all passes
    };
    static constexpr int kStripes = 64;
    void build_tables(const VisibilityMap *map);
    void set_boxes();  // boxes_ from seen_
    float voxel_part(const Table &t, const Vec3 &p, const Vec3 &d) const;

    VoxelGrid grid_;
    MapGuideOptions options_;
    Vec3 cell_size_;
    std::vector<Voxel> voxels_;
    std::unique_ptr<std::mutex[]> locks_, bound_locks_;
    std::vector<BBox> seen_;   // per voxel: the bounds of the end points recorded in it, all passes
    std::vector<BBox> boxes_;  // per voxel: where the coming pass samples it as a target
    std::vector<float> inv_volume_;  // of boxes_
    int scale_exponent_ = 20;  // a record's fixed-point value is value · 2^scale_exponent_
    double pass_flux_ = 0;     // what the last pass recorded (to set the next exponent)
    uint64_t pass_records_ = 0, records_ = 0;
    std::vector<Table> tables_;
    std::vector<int32_t> table_of_voxel_;
};

}  // namespace neepp
