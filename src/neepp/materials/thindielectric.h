// Thin dielectric (Mitsuba's `thindielectric`): an infinitely thin slab, e.g. a window pane. Reflection
// sums all inter-reflections inside the slab, R' = R + T^2 R / (1 - R^2) = 2R / (1 + R); the rest passes
// straight through (wo = -wi, no refraction offset). Two-sided. Like Mitsuba, the straight-through lobe
// is reported as BSDFNull (part of BSDFDelta and BSDFTransmission).
//
// Mitsuba XML parameters (default):
//   int_ior                 float or IOR name  "bk7" (1.5046)
//   ext_ior                 float or IOR name  "air" (1.000277)
//   specular_reflectance    texture 1.0
//   specular_transmittance  texture 1.0
#pragma once
#include "neepp/base/bsdf.h"

namespace neepp {

class ThinDielectricBSDF final : public DeltaOnlyBSDF {
public:
    // Null textures mean 1.
    ThinDielectricBSDF(float int_ior, float ext_ior, TexturePtr specular_reflectance = nullptr,
                       TexturePtr specular_transmittance = nullptr);
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFDeltaReflection | BSDFNull; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, specular_reflectance_, specular_transmittance_); }

    // Slab reflectance R' for light arriving from wi (Mitsuba's eval_null_transmission is 1 - R' times
    // specular_transmittance: what a shadow ray passing through the pane keeps).
    float reflectance(const Vec3 &wi) const;
    Color null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const override;

private:
    float eta_;
    TexturePtr specular_reflectance_, specular_transmittance_;
};

}  // namespace neepp
