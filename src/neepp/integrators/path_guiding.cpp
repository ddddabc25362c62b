#include "neepp/integrators/path_guiding.h"

#include "neepp/base/shape.h"

namespace neepp {

VertexGuide guide_at(SDTree *tree, bool learn, const SurfaceInteraction &si, float bsdf_fraction) {
    VertexGuide g;
    const uint32_t flags = si.shape->bsdf_flags;
    if (!tree || (flags & BSDFDelta) || !(flags & BSDFSmooth)) return g;
    g.record = learn;
    g.leaf = tree->leaf_at(si.p);
    if (tree->can_guide(g.leaf)) {
        g.tree = tree;
        g.bsdf_fraction = bsdf_fraction;
        g.fold = !(flags & BSDFTransmission);
        const Vec3 n = si.sh_frame.n;
        g.up = dot(si.to_world(si.wi), n) >= 0 ? n : -n;
    }
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
    const Vec3 d = g.sample(u2);
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

void GuideRecorder::commit(SDTree &tree, const Color &L) const {
    for (int i = 0; i < n_; ++i) {
        const Vertex &v = v_[i];
        // Per channel, where the throughput lets the channel through; the tree keeps their mean.
        double arrived = 0;
        for (int c = 0; c < 3; ++c)
            if (v.beta[c] > 0) arrived += double(L[c] - v.L[c] - v.direct[c]) / double(v.beta[c]);
        tree.record(v.p, v.d, std::max(arrived, 0.0) / 3.0 / double(v.pdf));
    }
}

}  // namespace neepp
