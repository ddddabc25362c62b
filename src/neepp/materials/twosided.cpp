#include "neepp/materials/twosided.h"

#include <cmath>

namespace neepp {
namespace {
Vec3 flip_z(Vec3 v) { return {v.x, v.y, -v.z}; }
}  // namespace

Color TwoSidedBSDF::eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    return wi.z >= 0 ? front_->eval(ctx, si, wi, wo) : back_->eval(ctx, si, flip_z(wi), flip_z(wo));
}

float TwoSidedBSDF::pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    return wi.z >= 0 ? front_->pdf(ctx, si, wi, wo) : back_->pdf(ctx, si, flip_z(wi), flip_z(wo));
}

BSDFEval TwoSidedBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
                                const Vec3 &wo) const {
    return wi.z >= 0 ? front_->eval_pdf(ctx, si, wi, wo) : back_->eval_pdf(ctx, si, flip_z(wi), flip_z(wo));
}

Color TwoSidedBSDF::null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const {
    return wi.z >= 0 ? front_->null_transmission(si, wi) : back_->null_transmission(si, flip_z(wi));
}

BSDFSample TwoSidedBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                                Vec2 u2) const {
    if (wi.z >= 0) return front_->sample(ctx, si, wi, u1, u2);
    BSDFSample bs = back_->sample(ctx, si, flip_z(wi), u1, u2);
    bs.wo = flip_z(bs.wo);
    return bs;
}

}  // namespace neepp
