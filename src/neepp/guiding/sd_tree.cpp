#include "neepp/guiding/sd_tree.h"
#include "neepp/io/binary_io.h"

#include <atomic>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace neepp {

namespace {

constexpr uint64_t kMaxRecord = uint64_t(1) << 40;    // one record: 2^16 times the last pass's mean at most
constexpr uint64_t kSaturation = uint64_t(1) << 62;   // a slot's sum stops here rather than wrap
constexpr char kMagic[8] = {'N', 'E', 'E', 'P', 'P', 'S', 'D', '1'};


// min(sum + n, kSaturation), whichever order the additions come in (min(min(a + b, S) + c, S) = min(a + b + c, S)
// for non-negative terms): so a saturated slot is as reproducible as any other.
void saturating_add(uint64_t &slot, uint64_t n) {
    std::atomic_ref<uint64_t> a(slot);
    uint64_t old = a.load(std::memory_order_relaxed);
    while (!a.compare_exchange_weak(old, std::min(old + n, kSaturation), std::memory_order_relaxed)) {}
}

}  // namespace

SDTree::SDTree(const BBox &bounds, SDTreeOptions options) : options_(options) {
    const Vec3 e = bounds.valid() ? bounds.extent() : Vec3(1.f);
    // A margin, so that points on the scene's bounds are inside the cube.
    size_ = std::max(max_component(e), 1e-4f) * 1.001f;
    lo_ = (bounds.valid() ? bounds.center() : Vec3(0.f)) - Vec3(size_ * 0.5f);
    nodes_.push_back(SpatialNode{});
    leaves_.emplace_back();
    start_recording(leaves_.back());
}

void SDTree::start_recording(Leaf &leaf) const {
    leaf.recording = leaf.sampling.refined(options_.directional_threshold, options_.max_depth);
    leaf.recorded.assign(leaf.recording.slot_count(), 0);
    leaf.count = 0;
}

uint32_t SDTree::leaf_at(const Vec3 &p) const {
    Vec3 lo = lo_, hi = lo_ + Vec3(size_);
    uint32_t node = 0;
    while (nodes_[node].children) {
        const int axis = nodes_[node].axis;
        const float mid = 0.5f * (lo[axis] + hi[axis]);
        if (p[axis] < mid) {
            hi[axis] = mid;
            node = nodes_[node].children;
        } else {
            lo[axis] = mid;
            node = nodes_[node].children + 1;
        }
    }
    return nodes_[node].leaf;
}

float SDTree::pdf(uint32_t leaf, const Vec3 &d) const {
    double u, v;
    direction_to_square(d, u, v);
    return float(leaves_[leaf].sampling.pdf(u, v) * kSquareToSolidAngle);
}

Vec3 SDTree::sample(uint32_t leaf, Vec2 u) const {
    const DirectionalQuadtree::Sample s = leaves_[leaf].sampling.sample(u.x, u.y);
    return square_to_direction(s.u, s.v);
}

void SDTree::record(const Vec3 &p, const Vec3 &d, double value) {
    Leaf &leaf = leaves_[leaf_at(p)];
    std::atomic_ref<uint64_t>(leaf.count).fetch_add(1, std::memory_order_relaxed);
    if (!(value > 0)) return;
    const double scaled = std::ldexp(value, scale_exponent_);
    const uint64_t n = scaled >= double(kMaxRecord) ? kMaxRecord : uint64_t(std::llround(scaled));
    if (!n) return;
    double u, v;
    direction_to_square(d, u, v);
    saturating_add(leaf.recorded[leaf.recording.leaf_slot(u, v)], n);
}

void SDTree::update(int pass_spp) {
    // What was recorded becomes what is sampled.
    double energy = 0;
    uint64_t count = 0;
    std::vector<double> sums;
    for (Leaf &leaf : leaves_) {
        sums.resize(leaf.recorded.size());
        for (size_t i = 0; i < sums.size(); ++i) sums[i] = std::ldexp(double(leaf.recorded[i]), -scale_exponent_);
        leaf.sampling = leaf.recording;
        leaf.sampling.set_leaf_sums(sums);
        energy += leaf.sampling.total();
        count += leaf.count;
    }
    records_ = count;
    set_scale_from_energy();

    // Split leaves that saw many records; the halves inherit the trees and half the count each, and split
    // again while that is still over the threshold (as PPG's).
    const double threshold = options_.spatial_threshold * std::sqrt(double(std::max(pass_spp, 1)));
    for (size_t i = 0; i < nodes_.size(); ++i) {
        if (nodes_[i].children || leaves_.size() >= options_.max_leaves) continue;
        const uint32_t leaf = nodes_[i].leaf;
        if (!(double(leaves_[leaf].count) > threshold)) continue;
        leaves_[leaf].count /= 2;
        leaves_.push_back(leaves_[leaf]);
        const uint8_t axis = uint8_t((nodes_[i].axis + 1) % 3);
        nodes_[i].children = uint32_t(nodes_.size());
        nodes_.push_back({0, leaf, axis});
        nodes_.push_back({0, uint32_t(leaves_.size() - 1), axis});
    }
    for (Leaf &leaf : leaves_) start_recording(leaf);
}

void SDTree::set_scale_from_energy() {
    double energy = 0;
    for (const Leaf &leaf : leaves_) energy += leaf.sampling.total();
    if (energy > 0 && records_ > 0) scale_exponent_ = std::clamp(24 - std::ilogb(energy / double(records_)), -900, 900);
}

SDTree SDTree::merge(std::span<const SDTree *const> trees) {
    if (trees.empty()) throw std::invalid_argument("SDTree::merge: no trees");
    SDTree out;
    out.options_ = trees[0]->options_;
    out.lo_ = trees[0]->lo_;
    out.size_ = trees[0]->size_;
    for (const SDTree *t : trees) {
        if (!(t->lo_ == out.lo_) || t->size_ != out.size_) throw std::runtime_error("guide: merging trees of other scenes");
        out.records_ += t->records_;
    }
    // Every tree splits along x, y, z in turn from the same cube, so their nodes line up: walk them
    // together, each staying at its leaf where it splits no further.
    out.nodes_.push_back(SpatialNode{});
    auto build = [&](auto &&self, uint32_t at, const std::vector<uint32_t> &at_nodes) -> void {
        bool split = false;
        for (size_t i = 0; i < trees.size(); ++i) split |= trees[i]->nodes_[at_nodes[i]].children != 0;
        if (!split) {
            std::vector<const DirectionalQuadtree *> quadtrees;
            for (size_t i = 0; i < trees.size(); ++i)
                quadtrees.push_back(&trees[i]->leaves_[trees[i]->nodes_[at_nodes[i]].leaf].sampling);
            out.nodes_[at].leaf = uint32_t(out.leaves_.size());
            out.leaves_.emplace_back().sampling = DirectionalQuadtree::sum(quadtrees);
            return;
        }
        const uint32_t first = uint32_t(out.nodes_.size());
        const uint8_t axis = uint8_t((out.nodes_[at].axis + 1) % 3);
        out.nodes_[at].children = first;
        out.nodes_.push_back({0, 0, axis});
        out.nodes_.push_back({0, 0, axis});
        for (uint32_t side = 0; side < 2; ++side) {
            std::vector<uint32_t> below;
            for (size_t i = 0; i < trees.size(); ++i) {
                const SpatialNode &n = trees[i]->nodes_[at_nodes[i]];
                below.push_back(n.children ? n.children + side : at_nodes[i]);
            }
            self(self, first + side, below);
        }
    };
    build(build, 0, std::vector<uint32_t>(trees.size(), 0));
    out.set_scale_from_energy();
    for (Leaf &leaf : out.leaves_) out.start_recording(leaf);
    return out;
}

nlohmann::json SDTree::statistics() const {
    size_t quad_leaves = 0;
    int depth = 0;
    for (const Leaf &leaf : leaves_) {
        quad_leaves += leaf.sampling.leaf_count();
        depth = std::max(depth, leaf.sampling.depth());
    }
    return {{"spatial_leaves", leaves_.size()},
            {"directional_leaves_mean", leaves_.empty() ? 0.0 : double(quad_leaves) / double(leaves_.size())},
            {"directional_depth_max", depth},
            {"records_last_pass", records_}};
}

std::string SDTree::save() const {
    BinaryWriter w{std::string(kMagic, sizeof kMagic)};
    w.put(lo_.x);
    w.put(lo_.y);
    w.put(lo_.z);
    w.put(size_);
    w.put(int32_t(scale_exponent_));
    w.put(uint64_t(records_));
    w.put(uint32_t(nodes_.size()));
    for (const SpatialNode &n : nodes_) {
        w.put(n.children);
        w.put(n.leaf);
        w.put(n.axis);
    }
    w.put(uint32_t(leaves_.size()));
    for (const Leaf &leaf : leaves_) leaf.sampling.write(w.bytes);
    return std::move(w.bytes);
}

void SDTree::load(std::string_view bytes) {
    SDTree t = decode(bytes);
    if (!(t.lo_ == lo_) || t.size_ != size_) throw std::runtime_error("guide: the SD-tree covers another scene");
    const SDTreeOptions options = options_;
    *this = std::move(t);
    // The recording trees follow this tree's options, not the saved one's defaults.
    options_ = options;
    for (Leaf &leaf : leaves_) start_recording(leaf);
}

SDTree SDTree::decode(std::string_view bytes) {
    SDTree out;
    if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
        throw std::runtime_error("guide: not an SD-tree");
    BinaryReader r{bytes, sizeof kMagic, "guide: SD-tree"};
    Vec3 lo;
    lo.x = r.get<float>();
    lo.y = r.get<float>();
    lo.z = r.get<float>();
    const float size = r.get<float>();
    if (!(size > 0) || !std::isfinite(size)) throw std::runtime_error("guide: bad SD-tree cube");
    const int scale = r.get<int32_t>();
    const uint64_t records = r.get<uint64_t>();
    const uint32_t node_count = r.get<uint32_t>();
    if (node_count < 1 || node_count > bytes.size()) throw std::runtime_error("guide: bad SD-tree size");
    std::vector<SpatialNode> nodes(node_count);
    for (SpatialNode &n : nodes) {
        n.children = r.get<uint32_t>();
        n.leaf = r.get<uint32_t>();
        n.axis = r.get<uint8_t>();
    }
    const uint32_t leaf_count = r.get<uint32_t>();
    if (leaf_count < 1 || leaf_count > bytes.size()) throw std::runtime_error("guide: bad SD-tree size");
    for (size_t i = 0; i < nodes.size(); ++i) {
        const SpatialNode &n = nodes[i];
        if (n.axis > 2 || (n.children && (n.children <= i || n.children + 1 >= node_count)) ||
            (!n.children && n.leaf >= leaf_count))
            throw std::runtime_error("guide: bad SD-tree node");
    }
    std::vector<Leaf> leaves(leaf_count);
    for (Leaf &leaf : leaves) {
        leaf.sampling = DirectionalQuadtree::read(bytes, r.pos);
        out.start_recording(leaf);
    }
    if (r.pos != bytes.size()) throw std::runtime_error("guide: trailing bytes after the SD-tree");
    out.lo_ = lo;
    out.size_ = size;
    out.nodes_ = std::move(nodes);
    out.leaves_ = std::move(leaves);
    out.scale_exponent_ = std::clamp(scale, -900, 900);
    out.records_ = records;
    return out;
}

bool SDTree::operator==(const SDTree &o) const {
    if (!(lo_ == o.lo_) || size_ != o.size_ || scale_exponent_ != o.scale_exponent_ || nodes_.size() != o.nodes_.size() ||
        leaves_.size() != o.leaves_.size())
        return false;
    for (size_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].children != o.nodes_[i].children || nodes_[i].leaf != o.nodes_[i].leaf || nodes_[i].axis != o.nodes_[i].axis)
            return false;
    for (size_t i = 0; i < leaves_.size(); ++i)
        if (!(leaves_[i].sampling == o.leaves_[i].sampling) || !(leaves_[i].recording == o.leaves_[i].recording) ||
            leaves_[i].recorded != o.leaves_[i].recorded || leaves_[i].count != o.leaves_[i].count)
            return false;
    return true;
}

}  // namespace neepp
