// Lambertian reflector (Mitsuba's `diffuse`): one-sided, black when seen from below.
#pragma once
#include "neepp/base/bsdf.h"
#include "neepp/math/warp.h"

namespace neepp {

class DiffuseBSDF final : public BSDF {
public:
    explicit DiffuseBSDF(TexturePtr reflectance) : reflectance_(std::move(reflectance)) {}
    // f and its density in eval_pdf alone; eval is its first half. pdf is its second without the texture
    // lookup, for callers that need only the density (BDPT's reverse densities).
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override {
        return eval_pdf(ctx, si, wi, wo).f;
    }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &wi, const Vec3 &wo) const override {
        return density(wi, wo);
    }
    BSDFEval eval_pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFDiffuseReflection; }
    bool needs_tangents() const override { return false; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, reflectance_); }
    const TexturePtr &reflectance() const { return reflectance_; }

private:
    // Cosine-weighted over the upper hemisphere, for a wi above it.
    static float density(const Vec3 &wi, const Vec3 &wo) {
        return cos_theta(wi) <= 0 || cos_theta(wo) <= 0 ? 0.f : square_to_cosine_hemisphere_pdf(wo);
    }
    TexturePtr reflectance_;
};

}  // namespace neepp
