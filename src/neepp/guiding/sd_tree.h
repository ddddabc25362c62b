// Practical Path Guiding's SD-tree (Müller, Gross, Novák 2017): a binary tree over space whose leaves
// each hold two directional quadtrees, one that this pass samples (what the last pass recorded) and one
// that this pass records into (refined from the other). Between passes (update) the recorded one becomes
// the sampled one, a leaf that received more than c·√(pass spp) records is split in two (the halves
// inherit its trees), and each leaf's next recording tree is refined by the energy just recorded.
//
// Records arrive from every render thread at once. Each is summed into its recording quadtree's leaf as a
// fixed-point integer (saturating), and integer sums do not depend on the order of the additions: the
// tree a pass leaves is a function of what was recorded, not of the threads' timing, so images are the
// same to the bit for a seed and thread count, as the visibility map's integer counts make them.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>
#include <nlohmann/json.hpp>
#include "neepp/guiding/directional_quadtree.h"
#include "neepp/math/bbox.h"

namespace neepp {

struct SDTreeOptions {
    double spatial_threshold = 12000;      // c: a leaf splits past c·√(pass spp) records (the paper's value)
    double directional_threshold = 0.01;   // ρ: a quadrant splits holding more than this share of the energy
    int max_depth = 20;                    // of a directional quadtree
    uint32_t max_leaves = 1u << 14;        // spatial leaves at most (memory)
};

class SDTree {
public:
    // The tree covers the cube around `bounds` (a cube, so that splits along x, y, z in turn make cells
    // of similar shape).
    explicit SDTree(const BBox &bounds, SDTreeOptions options = {});

    // The spatial leaf a point is in (points outside the cube go to the nearest leaf).
    uint32_t leaf_at(const Vec3 &p) const;
    // The quadtree this pass samples at the leaf; guide only where it holds energy.
    const DirectionalQuadtree &sampling(uint32_t leaf) const { return leaves_[leaf].sampling; }
    bool can_guide(uint32_t leaf) const { return leaves_[leaf].sampling.total() > 0; }
    // Solid-angle density and sampling of the leaf's sampled quadtree (can_guide(leaf) for sample).
    float pdf(uint32_t leaf, const Vec3 &d) const;
    Vec3 sample(uint32_t leaf, Vec2 u) const;

    // Records an estimate `value` (≥ 0) of the energy arriving at p from direction d, divided by the density
    // of having sampled d: thread-safe, and the result independent of the order of calls.
    void record(const Vec3 &p, const Vec3 &d, double value);
    // Between passes, single-threaded: what was recorded becomes what is sampled; leaves split and
    // recording quadtrees are refined (see above). pass_spp: samples per pixel of the pass just ended.
    void update(int pass_spp);

    size_t leaf_count() const { return leaves_.size(); }
    uint64_t records() const { return records_; }  // in the last pass update() closed
    nlohmann::json statistics() const;

    // Exact bytes of the whole tree, between passes (nothing recorded since the last update()).
    std::string save() const;
    void load(std::string_view bytes);  // throws std::runtime_error if malformed or for another scene's cube
    static SDTree decode(std::string_view bytes);  // a tree from save()'s bytes, whatever its cube
    // Distributed rendering: the trees that renders of several sample ranges learned (each from the same
    // start), as one: spatial leaves where any of them has one, each leaf's sampled quadtree the sum of
    // theirs at it (DirectionalQuadtree::sum), as if one render had recorded what each recorded last.
    // Deterministic, in the order given; all must cover the same cube.
    static SDTree merge(std::span<const SDTree *const> trees);
    bool operator==(const SDTree &o) const;

private:
    struct SpatialNode {
        uint32_t children = 0;  // index of the first of two children; 0: a leaf
        uint32_t leaf = 0;      // leaves only
        uint8_t axis = 0;       // the axis it splits, or would
    };
    struct Leaf {
        DirectionalQuadtree sampling, recording;
        std::vector<uint64_t> recorded;  // fixed-point energy per slot of `recording`
        uint64_t count = 0;              // records this pass
    };
    void start_recording(Leaf &leaf) const;
    SDTree() = default;
    void set_scale_from_energy();

    SDTreeOptions options_;
    Vec3 lo_;
    float size_ = 1;
    std::vector<SpatialNode> nodes_;
    std::vector<Leaf> leaves_;
    // A record's fixed-point value is value · 2^scale_exponent_; the exponent follows the mean record of
    // the last pass (a power of two, so that scaling is exact) and leaves ~2^24 steps below the mean.
    int scale_exponent_ = 24;
    uint64_t records_ = 0;
};

}  // namespace neepp
