// The directional half of Practical Path Guiding's SD-tree (Müller, Gross, Novák 2017): a quadtree over
// the unit square, which the cylindrical mapping (cos θ, φ) takes onto the sphere with a constant Jacobian
// (dω = 4π du dv), so a density piecewise constant on the square is piecewise constant in solid angle.
// Each node holds the energy of its four quadrants; sampling descends by those energies, and the density
// of a point is the product of the quadrant shares along the same descent: 4^depth times its leaf's share
// of the total, to which the product telescopes, formed alike by both, so the two agree to the bit.
// Doubles throughout: a leaf at depth 20 is 2^-21 wide, and the product of 20 shares must not drift.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>
#include "neepp/math/vec.h"

namespace neepp {

// The cylindrical mapping: u = (cos θ + 1) / 2 with θ from +z, v = φ / 2π, both in [0, 1).
Vec3 square_to_direction(double u, double v);
void direction_to_square(const Vec3 &d, double &u, double &v);
// Solid-angle density of a density on the square: the mapping's area is 4π.
constexpr double kSquareToSolidAngle = 0.07957747154594766788;  // 1 / 4π

class DirectionalQuadtree {
public:
    // Quadrant q of a node is x half (q & 1) and y half (q >> 1). child[q] == 0: the quadrant is a leaf
    // (the root, node 0, is nobody's child); sum[q]: the energy recorded in the quadrant.
    struct Node {
        std::array<uint32_t, 4> child{};
        std::array<double, 4> sum{};
    };
    struct Sample {
        double u = 0, v = 0;  // the point on the square
        double pdf = 0;       // its density on the square
    };

    DirectionalQuadtree() : nodes_(1) {}  // one node, four empty leaves

    const std::vector<Node> &nodes() const { return nodes_; }
    double total() const;
    // A leaf quadrant is addressed as node * 4 + q ("slot"); slot_count() covers every quadrant.
    size_t slot_count() const { return nodes_.size() * 4; }
    uint32_t leaf_slot(double u, double v) const;
    size_t leaf_count() const;
    int depth() const;  // of the deepest node; the root's is 1

    // Density on the square (integrates to 1 when total() > 0); zero in leaves with no energy, and
    // everywhere while total() is zero.
    double pdf(double u, double v) const;
    // A point with the density pdf() gives it, from two uniform numbers in [0, 1). Needs total() > 0.
    Sample sample(double u0, double u1) const;

    // The energies: each leaf quadrant's from slot_sums (indexed by slot; interior slots are not read),
    // each interior quadrant's the total of its child.
    void set_leaf_sums(std::span<const double> slot_sums);
    // PPG's refinement, for the next pass to record into: a quadrant holding more than `threshold` of
    // the total energy is subdivided (down to max_depth), one holding less becomes a leaf, so cells shrink
    // where energy arrives; where this tree has no node yet, its energy is taken as spread evenly. With no
    // energy at all, every quadrant counts 4^-depth (uniform refinement). The result holds no energy.
    DirectionalQuadtree refined(double threshold, int max_depth) const;

    // The sum of several trees' energies, on the union of their cells (a leaf of one inside another's
    // finer cells counts as spread evenly over them): what recording all their records would have given
    // on that union. Summed in the order given.
    static DirectionalQuadtree sum(std::span<const DirectionalQuadtree *const> trees);

    // Bytes for checkpoints and merges: topology and energies, exactly.
    void write(std::string &out) const;
    // Reads what write() wrote from data at offset (advanced past it); throws std::runtime_error if malformed.
    static DirectionalQuadtree read(std::string_view data, size_t &offset);
    bool operator==(const DirectionalQuadtree &o) const;

private:
    std::vector<Node> nodes_;  // children after their parents
};

}  // namespace neepp
