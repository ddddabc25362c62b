// Rough plastic (Mitsuba's `roughplastic`): a diffuse base under a rough dielectric coating, one-sided.
// Like Mitsuba it precomputes the coating's directional transmittance (64 entries over cos theta,
// linearly interpolated) and its hemispherical internal reflectance, and picks the glossy lobe with
// probability (1 - T(wi)) * w_s against T(wi) * (1 - w_s), w_s the specular sampling weight.
//
// Mitsuba XML parameters (default):
//   distribution          string  "beckmann"  "beckmann" or "ggx" (parse_microfacet_type)
//   alpha                 float   0.1         isotropic roughness (anisotropic roughness is rejected)
//   sample_visible        bool    true        sample visible normals (the precomputation always does)
//   int_ior               float or IOR name  "polypropylene" (1.49)  must differ from ext_ior
//   ext_ior               float or IOR name  "air" (1.000277)
//   diffuse_reflectance   texture 0.5
//   specular_reflectance  texture 1.0
//   nonlinear             bool    false
#pragma once
#include <array>
#include "neepp/base/bsdf.h"
#include "neepp/materials/microfacet.h"

namespace neepp {

class RoughPlasticBSDF final : public JointEvalBSDF {
public:
    // A null specular_reflectance means 1.
    RoughPlasticBSDF(MicrofacetType type, float alpha, float int_ior, float ext_ior, TexturePtr diffuse_reflectance,
                     TexturePtr specular_reflectance = nullptr, bool nonlinear = false, bool sample_visible = true);
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFGlossyReflection | BSDFDiffuseReflection; }
    bool needs_tangents() const override { return false; }  // isotropic
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, diffuse_reflectance_, specular_reflectance_); }

    static constexpr int kTransmittanceRes = 64;
    // Exposed for tests: the precomputed coating transmittance at cos theta and the internal reflectance.
    float external_transmittance(float cos_theta) const;
    float internal_reflectance() const { return internal_reflectance_; }

private:
    // Probability of sampling the specular lobe, from the coating's transmittance t_i toward wi.
    float prob_specular(float t_i) const;

    MicrofacetDistribution distr_;
    float eta_, inv_eta_2_;
    TexturePtr diffuse_reflectance_, specular_reflectance_;
    bool nonlinear_;
    float specular_sampling_weight_;
    std::array<float, kTransmittanceRes> external_transmittance_;
    float internal_reflectance_;
};

}  // namespace neepp
