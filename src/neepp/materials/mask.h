// Mitsuba's `mask`: an opacity texture; with probability 1 - opacity light passes straight through
// (a null, delta-transmission event), otherwise the nested BSDF scatters it.
#pragma once
#include <algorithm>
#include "neepp/materials/nesting_bsdf.h"

namespace neepp {

class MaskBSDF final : public NestingBSDF {
public:
    MaskBSDF(TexturePtr opacity, BSDFPtr nested)
        : NestingBSDF({nested.get()}, BSDFNull), opacity_(std::move(opacity)), nested_(std::move(nested)) {}
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    // What the mask lets through, and what its nested BSDF does where it is opaque.
    Color null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    void prefetch(const SurfaceInteraction &si) const override {
        opacity_->prefetch(si);
        nested_->prefetch(si);
    }

private:
    float opacity(const SurfaceInteraction &si) const { return std::clamp(opacity_->eval_1(si), 0.f, 1.f); }
    TexturePtr opacity_;
    BSDFPtr nested_;
};

}  // namespace neepp
