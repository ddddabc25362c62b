// Mitsuba's `mask`: an opacity texture; with probability 1 - opacity light passes straight through
// (a null, delta-transmission event), otherwise the nested BSDF scatters it.
#pragma once
#include <algorithm>
#include "neepp/base/bsdf.h"

namespace neepp {

class MaskBSDF final : public BSDF {
public:
    MaskBSDF(TexturePtr opacity, BSDFPtr nested)
        : opacity_(std::move(opacity)), nested_(std::move(nested)), flags_(nested_->flags() | BSDFNull),
          tangents_(nested_->needs_tangents()) {}
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return flags_; }  // read once (TwoSidedBSDF says why)
    void prefetch(const SurfaceInteraction &si) const override {
        opacity_->prefetch(si);
        nested_->prefetch(si);
    }
    bool needs_tangents() const override { return tangents_; }

private:
    float opacity(const SurfaceInteraction &si) const { return std::clamp(opacity_->eval_1(si), 0.f, 1.f); }
    TexturePtr opacity_;
    BSDFPtr nested_;
    uint32_t flags_;
    bool tangents_;
};

}  // namespace neepp
