#include "neepp/materials/mask.h"

#include "neepp/materials/null.h"

namespace neepp {

Color MaskBSDF::eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    return nested_->eval(ctx, si, wi, wo) * opacity(si);
}

float MaskBSDF::pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    return nested_->pdf(ctx, si, wi, wo) * opacity(si);
}

BSDFEval MaskBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    BSDFEval e = nested_->eval_pdf(ctx, si, wi, wo);
    const float a = opacity(si);
    return {e.f * a, e.pdf * a};
}

Color MaskBSDF::null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const {
    const float a = opacity(si);
    return Color(1.f - a) + nested_->null_transmission(si, wi) * a;
}

BSDFSample MaskBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                            Vec2 u2) const {
    float a = opacity(si);
    // Pass through: a null event chosen with probability 1 - a, weight (1-a)/(1-a).
    if (u1 >= a) return NullBSDF::pass_through(wi, 1.f - a, Color(1.f));
    BSDFSample bs = nested_->sample(ctx, si, wi, u1 / a, u2);
    bs.pdf *= a;  // f is scaled by a too, so the weight f/pdf is unchanged
    return bs;
}

}  // namespace neepp
