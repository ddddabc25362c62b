#include "neepp/integrators/path_guiding.h"

#include "neepp/base/shape.h"

namespace neepp {

namespace {

bool guidable(const SurfaceInteraction &si) {
    const uint32_t flags = si.shape->bsdf_flags;
    return !(flags & BSDFDelta) && (flags & BSDFSmooth);
}

void set_mixture(VertexGuide &g, const SurfaceInteraction &si, float bsdf_fraction) {
    g.bsdf_fraction = bsdf_fraction;
    g.fold = !(si.shape->bsdf_flags & BSDFTransmission);
    const Vec3 n = si.sh_frame.n;
    g.up = dot(si.to_world(si.wi), n) >= 0 ? n : -n;
}

}  // namespace

VertexGuide guide_at(const SDTree *tree, const MapGuide *map, bool learn, const SurfaceInteraction &si,
                     float bsdf_fraction, float tree_share) {
    VertexGuide g;
    if ((!tree && !map) || !guidable(si)) return g;
    g.record = learn;
    if (tree) {
        g.leaf = tree->leaf_at(si.p);
        if (tree->can_guide(g.leaf)) g.tree = tree;
    }
    if (map) {
        if (const MapGuide::Table *t = map->table_at(si.p)) {
            g.map = map;
            g.table = t;
            g.p = si.p;
        }
    }
    // A share of 0 or 1 is one guide alone: the other is left out, not evaluated at zero weight.
    if (g.tree && g.table && tree_share <= 0.f) g.tree = nullptr;
    if (g.tree && g.table && tree_share >= 1.f) g.table = nullptr;
    if (!g.guides()) return g;
    g.tree_share = !g.table ? 1.f : !g.tree ? 0.f : tree_share;
    set_mixture(g, si, bsdf_fraction);
    return g;
}

BSDFSample sample_guided(const VertexGuide &g, const BSDF &bsdf, const SurfaceInteraction &si, float u_choice, float u1,
                         Vec2 u2, float &bsdf_pdf) {
    if (u_choice < g.bsdf_fraction) {
        BSDFSample bs = bsdf.sample(BSDFContext{}, si, si.wi, u1, u2);
        if (!bs.valid()) return bs;
        bsdf_pdf = bs.pdf;
        const float pdf = g.pdf(si.to_world(bs.wo), bs.pdf);
        bs.weight *= bs.pdf / pdf;  // f·|cos| / mixture pdf
        bs.pdf = pdf;
        return bs;
    }
    BSDFSample bs;
    // The choice's own uniform, rescaled to [0, 1), picks the map guide's cell.
    const float u_pick = std::min((u_choice - g.bsdf_fraction) / (1.f - g.bsdf_fraction), kOneMinusEpsilon);
    const Vec3 d = g.sample(u_pick, u1, u2);
    if (!(squared_norm(d) > 0)) return BSDFSample{};
    bs.wo = si.to_local(d);
    const BSDFEval e = bsdf.eval_pdf(BSDFContext{}, si, si.wi, bs.wo);
    // The tree's density of d as pdf() gives it, which is the one the BSDF-sampled branch sees too.
    const float pdf = g.pdf(d, e.pdf);
    if (!(pdf > 0) || is_black(e.f)) return BSDFSample{};
    bsdf_pdf = e.pdf;
    bs.pdf = pdf;
    bs.weight = e.f / pdf;
    bs.sampled_flags = bs.wo.z * si.wi.z > 0 ? BSDFGlossyReflection : BSDFGlossyTransmission;
    return bs;
}

double GuideRecorder::Vertex::arrived(const Color &L_end) const {
    double sum = 0;
    for (int c = 0; c < 3; ++c)
        if (beta[c] > 0) sum += double(L_end[c] - L[c] - direct[c]) / double(beta[c]);
    return std::max(sum, 0.0) / 3.0;
}

void GuideRecorder::commit(SDTree &tree, const Color &L) const {
    for (int i = 0; i < n_; ++i) tree.record(v_[i].p, v_[i].d, v_[i].arrived(L) / double(v_[i].pdf));
}

void GuideRecorder::commit(MapGuide &map, const Color &L) const {
    for (int i = 0; i < n_; ++i) {
        const Vertex &v = v_[i];
        const uint32_t target = v.end_kind == kOpen ? MapGuide::kNoTarget : map.target_of(v.end, v.d, v.end_kind == kEscaped);
        const double arrived = v.arrived(L);
        map.record(v.p, target, arrived / double(v.pdf), arrived, v.end);
    }
}

}  // namespace neepp
