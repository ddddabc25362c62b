// Lambertian reflector (Mitsuba's `diffuse`): one-sided, black when seen from below.
#pragma once
#include "neepp/materials/bsdf.h"

namespace neepp {

class DiffuseBSDF final : public BSDF {
public:
    explicit DiffuseBSDF(TexturePtr reflectance) : reflectance_(std::move(reflectance)) {}
    Color eval(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    // Both at once, as next event estimation asks at every diffuse vertex: one call and one test of the
    // hemispheres instead of two of each.
    BSDFEval eval_pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFDiffuseReflection; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, reflectance_); }
    const TexturePtr &reflectance() const { return reflectance_; }

private:
    TexturePtr reflectance_;
};

}  // namespace neepp
