// Smooth dielectric (Mitsuba's `dielectric`): two-sided delta reflection and refraction, each picked with
// its Fresnel probability. Refraction scales radiance by 1/eta^2 (eta along the direction of travel) in
// TransportMode::Radiance only; importance is not compressed by the change of solid angle.
//
// Mitsuba XML parameters (default):
//   int_ior                 float or IOR name  "bk7" (1.5046)   interior IOR (lookup_dielectric_ior)
//   ext_ior                 float or IOR name  "air" (1.000277) exterior IOR
//   specular_reflectance    texture 1.0   multiplier (not physical)
//   specular_transmittance  texture 1.0   multiplier (not physical)
#pragma once
#include "neepp/base/bsdf.h"

namespace neepp {

class DielectricBSDF final : public DeltaOnlyBSDF {
public:
    // Null textures mean 1.
    DielectricBSDF(float int_ior, float ext_ior, TexturePtr specular_reflectance = nullptr,
                   TexturePtr specular_transmittance = nullptr);
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFDeltaReflection | BSDFDeltaTransmission; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, specular_reflectance_, specular_transmittance_); }
    float eta() const { return eta_; }

private:
    float eta_;
    TexturePtr specular_reflectance_, specular_transmittance_;
};

}  // namespace neepp
