#include "neepp/materials/blendbsdf.h"

#include <algorithm>

namespace neepp {

float BlendBSDF::weight(const SurfaceInteraction &si) const { return std::clamp(weight_->eval_1(si), 0.f, 1.f); }

Color BlendBSDF::null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const {
    const float w = weight(si);
    return first_->null_transmission(si, wi) * (1.f - w) + second_->null_transmission(si, wi) * w;
}

Color BlendBSDF::eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    const float w = weight(si);
    return first_->eval(ctx, si, wi, wo) * (1.f - w) + second_->eval(ctx, si, wi, wo) * w;
}

float BlendBSDF::pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    const float w = weight(si);
    return first_->pdf(ctx, si, wi, wo) * (1.f - w) + second_->pdf(ctx, si, wi, wo) * w;
}

BSDFEval BlendBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    const float w = weight(si);
    const BSDFEval a = first_->eval_pdf(ctx, si, wi, wo), b = second_->eval_pdf(ctx, si, wi, wo);
    return {a.f * (1.f - w) + b.f * w, a.pdf * (1.f - w) + b.pdf * w};
}

BSDFSample BlendBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                             Vec2 u2) const {
    const float w = weight(si);
    // The second with probability w (u1 < w, so that w = 0 never picks it), u1 rescaled for the one picked.
    const bool second = u1 < w;
    const float p = second ? w : 1.f - w;
    const BSDF &picked = second ? *second_ : *first_, &other = second ? *first_ : *second_;
    BSDFSample bs = picked.sample(ctx, si, wi, second ? u1 / w : (u1 - w) / (1.f - w), u2);
    if (!(bs.pdf > 0)) return {};
    if (bs.sampled_flags & BSDFDelta) {
        // A delta direction has no density under the other BSDF: only the pick's probability scales it,
        // in f and pdf alike. (Mitsuba 3.9 adds the other's density here too, a density to a probability.)
        bs.pdf *= p;
        return bs;
    }
    // Any direction is reachable from either: the blend's density and eval, as one-sample MIS over the two.
    const BSDFEval o = other.eval_pdf(ctx, si, wi, bs.wo);
    const float pdf = p * bs.pdf + (1.f - p) * o.pdf;
    const Color f = bs.weight * (p * bs.pdf) + o.f * (1.f - p);
    bs.pdf = pdf;
    bs.weight = pdf > 0 ? f / pdf : Color(0.f);
    return bs;
}

}  // namespace neepp
