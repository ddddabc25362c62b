// Path guiding at a scattering vertex of the path integrator (both forms): the next direction drawn by
// one-sample MIS between the BSDF (probability bsdf_fraction) and a guide, weighted by the mixture's
// density. The guide is practical path guiding's SD-tree (Müller et al. 2017; guiding=sdtree), the
// visibility map's guide (guiding=map, map_guide.h), or their mixture (guiding=sdtree+map: three
// strategies, the guide's share split between the two). The BSDF's share is never zero, so every direction
// the BSDF can reach stays reachable whatever the guide says: the estimate is unbiased for any guide, a
// wrong one only costs variance. Vertices whose BSDF has a delta part are left to the BSDF.
#pragma once
#include <algorithm>
#include <array>
#include "neepp/base/bsdf.h"
#include "neepp/base/interaction.h"
#include "neepp/guiding/map_guide.h"
#include "neepp/guiding/sd_tree.h"

namespace neepp {

struct VertexGuide {
    const SDTree *tree = nullptr;  // guiding=sdtree: the tree and the vertex's leaf
    uint32_t leaf = 0;
    const MapGuide *map = nullptr;  // guiding=map: the guide, the vertex voxel's table and the vertex
    const MapGuide::Table *table = nullptr;
    Vec3 p;
    float bsdf_fraction = 1.f;
    // The tree's share of the guide's density where both guide (1 with the tree alone, 0 with the map's).
    float tree_share = 1.f;
    bool record = false;           // the vertex's sampled direction is recorded into the tree
    // Where the BSDF only reflects, the guide's directions are folded onto the side it reflects to (that
    // of `up`, the shading normal turned toward wi): a direction behind the surface is mirrored across
    // it, so no guided sample is lost to a zero BSDF, and the folded density at d is the tree's at d plus
    // its at d's mirror image.
    bool fold = false;
    Vec3 up;
    static Vec3 mirror(const Vec3 &d, const Vec3 &n) { return d - n * (2.f * dot(d, n)); }
    // Whether a guide samples here (else the BSDF alone).
    bool guides() const { return tree || table; }
    // The unfolded guide's density of d (the mixture's, where both guide), and a direction from it (u_pick:
    // the tree or the map's guide, then the latter's cell; u1 the point in it; the tree reads u2 only).
    float raw_pdf(const Vec3 &d) const {
        if (!table) return tree->pdf(leaf, d);
        if (!tree) return map->pdf(*table, p, d);
        return tree_share * tree->pdf(leaf, d) + (1.f - tree_share) * map->pdf(*table, p, d);
    }
    Vec3 raw_sample(float u_pick, float u1, Vec2 u2) const {
        if (!table) return tree->sample(leaf, u2);
        if (!tree) return map->sample(*table, p, u_pick, u1, u2);
        if (u_pick < tree_share) return tree->sample(leaf, u2);
        return map->sample(*table, p, std::min((u_pick - tree_share) / (1.f - tree_share), kOneMinusEpsilon), u1, u2);
    }
    // The guide's own density of direction d.
    float guide_pdf(const Vec3 &d) const {
        if (!fold) return raw_pdf(d);
        if (!(dot(d, up) > 0)) return 0.f;
        return raw_pdf(d) + raw_pdf(mirror(d, up));
    }
    // A direction from the guide alone, with density guide_pdf (a zero vector: none).
    Vec3 sample(float u_pick, float u1, Vec2 u2) const {
        const Vec3 d = raw_sample(u_pick, u1, u2);
        return fold && dot(d, up) < 0 ? mirror(d, up) : d;
    }
    // The density with which the vertex samples world direction d, the BSDF's own density being bsdf_pdf:
    // what weighs the sample.
    float pdf(const Vec3 &d, float bsdf_pdf) const {
        return guides() ? bsdf_fraction * bsdf_pdf + (1.f - bsdf_fraction) * guide_pdf(d) : bsdf_pdf;
    }
};

// The guide at a vertex: the tree's leaf where it can guide, the map guide's table where the vertex's voxel
// has one, either or both (null: that guide is off; neither: the BSDF samples alone). learn: the vertex's
// direction is recorded. tree_share: the tree's share of the guide where both guide.
VertexGuide guide_at(const SDTree *tree, const MapGuide *map, bool learn, const SurfaceInteraction &si,
                     float bsdf_fraction, float tree_share);

// The next direction by one-sample MIS: u_choice picks the strategy, (u1, u2) drive it. The sample's pdf
// is the mixture's and its weight f·|cos| / pdf; bsdf_pdf receives the BSDF's own density of it. A
// direction drawn from the tree carries eta 1 (its only reader is Russian roulette, which any value keeps
// unbiased).
//
// MIS against next event estimation weighs the BSDF strategy by the BSDF's own density, not the
// mixture's: power-heuristic weights formed from any densities that are zero only where the strategies'
// are still sum to one, so the estimate stays unbiased, and the guide's density is then not asked for
// NEE's weight (two of the up to six quadtree lookups of a vertex where the surface folds the guide).
BSDFSample sample_guided(const VertexGuide &g, const BSDF &bsdf, const SurfaceInteraction &si, float u_choice, float u1,
                         Vec2 u2, float &bsdf_pdf);

// The guided vertices of one path, each with what the path had gathered and its throughput when the
// vertex's direction was chosen: what the path gathers later, divided by that throughput, is the radiance
// that arrived along the direction, and that over the direction's density is PPG's record.
class GuideRecorder {
public:
    // The vertex at path depth `depth` (the camera's first hit is 0).
    void add(int depth, const Vec3 &p, const Vec3 &d, float pdf, const Color &beta, const Color &L) {
        if (n_ < int(v_.size())) v_[n_++] = {p, d, Vec3(0.f), pdf, beta, L, Color(0.f), depth, kOpen};
    }
    // Where the ray of the direction chosen at depth `depth` ended: at `end`, or it left the scene (the
    // map guide files the record under that cell).
    void ended(int depth, const Vec3 &end, bool escaped) {
        if (n_ > 0 && v_[n_ - 1].depth == depth && v_[n_ - 1].end_kind == kOpen) {
            v_[n_ - 1].end = end;
            v_[n_ - 1].end_kind = escaped ? kEscaped : kHit;
        }
    }
    // Emission that the direction chosen at depth `depth` found directly, as the path gathered it (its
    // MIS weight included): left out of that vertex's record when the guide learns only the light that
    // next event estimation does not bring (PathOptions::guiding_learn_direct false).
    void found_emission(int depth, const Color &contribution) {
        if (n_ > 0 && v_[n_ - 1].depth == depth) v_[n_ - 1].direct += contribution;
    }
    // Records every vertex into the guide, L being all the path gathered.
    void commit(SDTree &tree, const Color &L) const;
    void commit(MapGuide &map, const Color &L) const;
    void clear() { n_ = 0; }

private:
    enum EndKind : uint8_t { kOpen, kHit, kEscaped };
    struct Vertex {
        Vec3 p, d, end;
        float pdf;
        Color beta, L, direct;
        int depth;
        EndKind end_kind;
        // The radiance that arrived along d: what the path gathered after the vertex over its throughput
        // then, per channel where the throughput lets the channel through, their mean.
        double arrived(const Color &L_end) const;
    };
    std::array<Vertex, 64> v_;  // longer paths record their first 64 vertices
    int n_ = 0;
};

}  // namespace neepp
