// Mitsuba's `blendbsdf`: (1 - w) times the first nested BSDF plus w times the second, w a float or a
// texture clamped to [0, 1]. Sampling picks the second with probability w and the first otherwise; a
// direction from a smooth lobe then gets the blend's own density, the two pdfs weighted alike, so that its
// weight is the blended eval over it.
#pragma once
#include "neepp/materials/nesting_bsdf.h"

namespace neepp {

class BlendBSDF final : public NestingBSDF {
public:
    BlendBSDF(TexturePtr weight, BSDFPtr first, BSDFPtr second)
        : NestingBSDF({first.get(), second.get()}), weight_(std::move(weight)), first_(std::move(first)),
          second_(std::move(second)) {}
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    Color null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    void prefetch(const SurfaceInteraction &si) const override {
        weight_->prefetch(si);
        first_->prefetch(si);
        second_->prefetch(si);
    }

private:
    float weight(const SurfaceInteraction &si) const;
    TexturePtr weight_;
    BSDFPtr first_, second_;
};

}  // namespace neepp
