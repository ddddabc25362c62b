// Mitsuba's `twosided`: makes a one-sided BSDF (or a pair, front and back) reflect on both sides by
// mirroring directions seen from below into the upper hemisphere.
#pragma once
#include "neepp/materials/nesting_bsdf.h"

namespace neepp {

class TwoSidedBSDF final : public NestingBSDF {
public:
    TwoSidedBSDF(BSDFPtr front, BSDFPtr back)
        : NestingBSDF({front.get(), back ? back.get() : front.get()}), front_(std::move(front)),
          back_(back ? std::move(back) : front_) {}
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    Color null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    void prefetch(const SurfaceInteraction &si) const override { (si.wi.z >= 0 ? front_ : back_)->prefetch(si); }

private:
    BSDFPtr front_, back_;
};

}  // namespace neepp
