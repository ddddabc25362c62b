// Smooth conductor (Mitsuba's `conductor`): a one-sided perfect mirror with complex-IOR Fresnel.
//
// Mitsuba XML parameters (default):
//   material              string  "none"  named preset (lookup_conductor_ior); "none" = 100% reflecting mirror.
//                                         Giving both `material` (other than "none") and `eta` is an error.
//   eta                   texture 0.0     real part of the IOR (used when `eta` is given or material is "none")
//   k                     texture 1.0     imaginary part (absorption)
//   specular_reflectance  texture 1.0     multiplier (not physical)
#pragma once
#include "neepp/base/bsdf.h"

namespace neepp {

class ConductorBSDF final : public DeltaOnlyBSDF {
public:
    // A null specular_reflectance means 1.
    ConductorBSDF(TexturePtr eta, TexturePtr k, TexturePtr specular_reflectance = nullptr);
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFDeltaReflection; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, eta_, k_, specular_reflectance_); }

private:
    TexturePtr eta_, k_, specular_reflectance_;
};

}  // namespace neepp
