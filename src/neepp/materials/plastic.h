// Smooth plastic (Mitsuba's `plastic`): a diffuse base under a smooth dielectric coating, one-sided.
// The coating's delta reflection and the diffuse lobe (with internal scattering between base and coating)
// are sampled with probabilities proportional to Fresnel times Mitsuba's specular sampling weight.
//
// Mitsuba XML parameters (default):
//   int_ior               float or IOR name  "polypropylene" (1.49)  interior IOR (lookup_dielectric_ior)
//   ext_ior               float or IOR name  "air" (1.000277)         exterior IOR
//   diffuse_reflectance   texture 0.5    base albedo
//   specular_reflectance  texture 1.0    multiplier on the coating reflection (not physical)
//   nonlinear             bool    false  account for the base's color shift from internal scattering
#pragma once
#include "neepp/base/bsdf.h"

namespace neepp {

// Mitsuba's sampling weight of a coating's specular lobe: s_mean / (d_mean + s_mean) over texture means.
float specular_sampling_weight(const Texture &diffuse, const Texture &specular);

class PlasticBSDF final : public BSDF {
public:
    // A null specular_reflectance means 1.
    PlasticBSDF(float int_ior, float ext_ior, TexturePtr diffuse_reflectance, TexturePtr specular_reflectance = nullptr,
                bool nonlinear = false);
    Color eval(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFDeltaReflection | BSDFDiffuseReflection; }
    bool needs_tangents() const override { return false; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, diffuse_reflectance_, specular_reflectance_); }

private:
    float prob_specular(float f_i) const;
    Color diffuse_term(const SurfaceInteraction &si, float f_i, float f_o) const;

    float eta_, inv_eta_2_, fdr_int_;
    TexturePtr diffuse_reflectance_, specular_reflectance_;
    bool nonlinear_;
    float specular_sampling_weight_;
};

}  // namespace neepp
