#include "neepp/guiding/directional_quadtree.h"
#include "neepp/io/binary_io.h"

#include <cmath>
#include <cstring>
#include <deque>
#include <stdexcept>

namespace neepp {

namespace {
constexpr double kTwoPi = 6.283185307179586476925;

double quadrant_total(const DirectionalQuadtree::Node &n) { return (n.sum[0] + n.sum[1]) + (n.sum[2] + n.sum[3]); }

// Chooses one of two parts with probability share and (1 - share) by u, and rescales u to [0, 1) within
// the part chosen, so that the rest of the descent reuses it.
int choose(double share, double &u) {
    if (u < share) {
        u = u / share;
        return 0;
    }
    u = (u - share) / (1.0 - share);
    return 1;
}

double below_one(double u) { return std::min(u, std::nextafter(1.0, 0.0)); }

}  // namespace

Vec3 square_to_direction(double u, double v) {
    const double cos_theta = 2.0 * u - 1.0;
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    const double phi = kTwoPi * v;
    return {float(sin_theta * std::cos(phi)), float(sin_theta * std::sin(phi)), float(cos_theta)};
}

void direction_to_square(const Vec3 &d, double &u, double &v) {
    const double cos_theta = std::clamp(double(d.z), -1.0, 1.0);
    u = below_one((cos_theta + 1.0) * 0.5);
    double phi = std::atan2(double(d.y), double(d.x));
    if (phi < 0) phi += kTwoPi;
    v = below_one(phi / kTwoPi);
}

double DirectionalQuadtree::total() const { return quadrant_total(nodes_[0]); }

uint32_t DirectionalQuadtree::leaf_slot(double u, double v) const {
    uint32_t node = 0;
    for (;;) {
        // Local coordinates double at each level: exact in binary, so pdf() and sample() see the same cell.
        const int ix = u >= 0.5, iy = v >= 0.5;
        const int q = ix | (iy << 1);
        u = 2.0 * u - ix;
        v = 2.0 * v - iy;
        const uint32_t c = nodes_[node].child[q];
        if (!c) return node * 4 + uint32_t(q);
        node = c;
    }
}

size_t DirectionalQuadtree::leaf_count() const {
    size_t n = 0;
    for (const Node &node : nodes_)
        for (uint32_t c : node.child) n += c == 0;
    return n;
}

int DirectionalQuadtree::depth() const {
    std::vector<int> depth(nodes_.size(), 1);
    int deepest = 1;
    for (size_t i = 0; i < nodes_.size(); ++i) {
        deepest = std::max(deepest, depth[i]);
        for (uint32_t c : nodes_[i].child)
            if (c) depth[c] = depth[i] + 1;
    }
    return deepest;
}

// The product of the shares 4·sum[q] / total along the descent telescopes (a child's total is its
// quadrant's sum in the parent, set_leaf_sums), so the density is 4^depth · leaf sum / root total: one
// division, where the product took one per level (the guide's pdf is asked up to four times a vertex);
// sample() forms its density the same way.
double DirectionalQuadtree::pdf(double u, double v) const {
    const double total = quadrant_total(nodes_[0]);
    if (!(total > 0)) return 0.0;
    uint32_t node = 0;
    int depth = 1;
    for (;; ++depth) {
        const Node &n = nodes_[node];
        const int ix = u >= 0.5, iy = v >= 0.5;
        const int q = ix | (iy << 1);
        u = 2.0 * u - ix;
        v = 2.0 * v - iy;
        if (!n.child[q]) return n.sum[q] > 0 ? std::ldexp(n.sum[q] / total, 2 * depth) : 0.0;
        node = n.child[q];
    }
}

DirectionalQuadtree::Sample DirectionalQuadtree::sample(double u0, double u1) const {
    Sample s;
    const double root_total = quadrant_total(nodes_[0]);
    double x0 = 0, y0 = 0, size = 1;  // the current node's cell
    uint32_t node = 0;
    for (int depth = 1;; ++depth) {
        const Node &n = nodes_[node];
        const double total = quadrant_total(n);
        // x half by the energy of its two quadrants, then y half within it.
        const int ix = choose((n.sum[0] + n.sum[2]) / total, u0);
        const int iy = choose(n.sum[ix] / (n.sum[ix] + n.sum[ix + 2]), u1);
        u0 = below_one(u0);
        u1 = below_one(u1);
        const int q = ix | (iy << 1);
        size *= 0.5;
        x0 += ix * size;
        y0 += iy * size;
        if (!n.child[q]) {
            s.pdf = std::ldexp(n.sum[q] / root_total, 2 * depth);  // as pdf() forms it, to the bit
            // Uniform in the leaf's cell; kept inside it, so that pdf() of the point descends here too.
            s.u = std::min(x0 + u0 * size, std::nextafter(x0 + size, 0.0));
            s.v = std::min(y0 + u1 * size, std::nextafter(y0 + size, 0.0));
            return s;
        }
        node = n.child[q];
    }
}

void DirectionalQuadtree::set_leaf_sums(std::span<const double> slot_sums) {
    if (slot_sums.size() < slot_count()) throw std::invalid_argument("set_leaf_sums: a sum per slot");
    for (size_t i = nodes_.size(); i-- > 0;) {
        Node &n = nodes_[i];
        for (int q = 0; q < 4; ++q) n.sum[q] = n.child[q] ? quadrant_total(nodes_[n.child[q]]) : slot_sums[i * 4 + q];
    }
}

DirectionalQuadtree DirectionalQuadtree::refined(double threshold, int max_depth) const {
    // Breadth first, so that children come after their parents and the same tree refines the same way.
    struct Item {
        uint32_t out;                // node in the refined tree
        int source;                  // node of this tree it copies, or -1 past this tree's leaves
        std::array<double, 4> sum;   // the energies its quadrants are judged by
        int depth;
    };
    DirectionalQuadtree out;
    const double total = this->total();
    std::deque<Item> queue{{0, 0, nodes_[0].sum, 1}};
    while (!queue.empty()) {
        const Item item = queue.front();
        queue.pop_front();
        for (int q = 0; q < 4; ++q) {
            const double fraction = total > 0 ? item.sum[q] / total : std::pow(0.25, item.depth);
            if (!(item.depth < max_depth && fraction > threshold)) continue;
            const uint32_t child = uint32_t(out.nodes_.size());
            out.nodes_.emplace_back();
            out.nodes_[item.out].child[q] = child;
            const uint32_t source_child = item.source >= 0 ? nodes_[item.source].child[q] : 0;
            if (source_child) {
                queue.push_back({child, int(source_child), nodes_[source_child].sum, item.depth + 1});
            } else {
                const double quarter = item.sum[q] / 4;
                queue.push_back({child, -1, {quarter, quarter, quarter, quarter}, item.depth + 1});
            }
        }
    }
    return out;
}

DirectionalQuadtree DirectionalQuadtree::sum(std::span<const DirectionalQuadtree *const> trees) {
    // Each input is, at the output node being built, either at one of its nodes or inside one of its
    // leaves (node -1), whose energy is split in four at each level further down.
    struct Source {
        const DirectionalQuadtree *tree;
        int node;
        double energy;
    };
    DirectionalQuadtree out;
    auto build = [&out](auto &&self, uint32_t at, const std::vector<Source> &sources) -> void {
        for (int q = 0; q < 4; ++q) {
            std::vector<Source> next;
            bool split = false;
            for (const Source &s : sources) {
                if (s.node < 0) {
                    next.push_back({s.tree, -1, s.energy / 4});
                    continue;
                }
                const Node &n = s.tree->nodes_[s.node];
                split |= n.child[q] != 0;
                next.push_back(n.child[q] ? Source{s.tree, int(n.child[q]), 0.0} : Source{s.tree, -1, n.sum[q]});
            }
            if (split) {
                const uint32_t child = uint32_t(out.nodes_.size());
                out.nodes_.emplace_back();
                out.nodes_[at].child[q] = child;
                self(self, child, next);
            } else {
                double e = 0;
                for (const Source &s : next) e += s.energy;
                out.nodes_[at].sum[q] = e;
            }
        }
    };
    std::vector<Source> roots;
    for (const DirectionalQuadtree *t : trees) roots.push_back({t, 0, 0.0});
    build(build, 0, roots);
    // Interior quadrants hold their child's total; children come after their parents.
    for (size_t i = out.nodes_.size(); i-- > 0;)
        for (int q = 0; q < 4; ++q)
            if (out.nodes_[i].child[q]) out.nodes_[i].sum[q] = quadrant_total(out.nodes_[out.nodes_[i].child[q]]);
    return out;
}

void DirectionalQuadtree::write(std::string &out) const {
    BinaryWriter w{std::move(out)};
    w.put(uint32_t(nodes_.size()));
    for (const Node &n : nodes_) {
        for (uint32_t c : n.child) w.put(c);
        for (double s : n.sum) w.put(s);
    }
    out = std::move(w.bytes);
}

DirectionalQuadtree DirectionalQuadtree::read(std::string_view data, size_t &offset) {
    BinaryReader r{data, offset, "guide: directional quadtree"};
    const uint32_t count = r.get<uint32_t>();
    if (count < 1 || count > (data.size() - r.pos) / (4 * (sizeof(uint32_t) + sizeof(double))))
        throw std::runtime_error("guide: bad directional quadtree size");
    DirectionalQuadtree t;
    t.nodes_.resize(count);
    for (uint32_t i = 0; i < count; ++i) {
        Node &n = t.nodes_[i];
        for (uint32_t &c : n.child) {
            c = r.get<uint32_t>();
            if (c != 0 && (c <= i || c >= count)) throw std::runtime_error("guide: bad directional quadtree child");
        }
        for (double &s : n.sum) {
            s = r.get<double>();
            if (!(s >= 0) || !std::isfinite(s)) throw std::runtime_error("guide: bad directional quadtree energy");
        }
    }
    offset = r.pos;
    return t;
}

bool DirectionalQuadtree::operator==(const DirectionalQuadtree &o) const {
    if (nodes_.size() != o.nodes_.size()) return false;
    for (size_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].child != o.nodes_[i].child || nodes_[i].sum != o.nodes_[i].sum) return false;
    return true;
}

}  // namespace neepp
