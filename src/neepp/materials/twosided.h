// Mitsuba's `twosided`: makes a one-sided BSDF (or a pair, front and back) reflect on both sides by
// mirroring directions seen from below into the upper hemisphere.
#pragma once
#include "neepp/base/bsdf.h"

namespace neepp {

class TwoSidedBSDF final : public BSDF {
public:
    // Its flags and tangent need are read once, here: asked of a chain of wrappers at every call, each
    // asking both of its nested BSDFs (one object twice, when the back is the front), they would cost
    // 2^depth calls.
    TwoSidedBSDF(BSDFPtr front, BSDFPtr back)
        : front_(std::move(front)), back_(back ? std::move(back) : front_),
          flags_(front_->flags() | back_->flags()), tangents_(front_->needs_tangents() || back_->needs_tangents()) {}
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return flags_; }
    void prefetch(const SurfaceInteraction &si) const override { (si.wi.z >= 0 ? front_ : back_)->prefetch(si); }
    bool needs_tangents() const override { return tangents_; }

private:
    BSDFPtr front_, back_;
    uint32_t flags_;
    bool tangents_;
};

}  // namespace neepp
