// Polarized plastic (Mitsuba's `pplastic`) as Mitsuba 3's RGB variants render it. Without polarization its
// Mueller matrices reduce to scalar Fresnel factors:
//   specular  F(wi.h) D(h) G(wi, wo) / (4 cos theta_i)            (a rough dielectric coating)
//   diffuse   (1 - F(cos theta_i)) (1 - F(cos theta_o)) rho / pi cos theta_o
// Unlike `roughplastic`, the diffuse base is seen through two smooth-interface transmissions, with no
// internal reflection summed and no tabulated rough transmittance; the lobe is chosen by the specular
// sampling weight alone. One-sided, as Mitsuba's.
//
// Mitsuba XML parameters (default):
//   diffuse_reflectance   texture 0.5
//   specular_reflectance  texture 1.0
//   distribution          string  "beckmann"  "beckmann" or "ggx"
//   alpha | alpha_u, alpha_v  texture 0.1
//   sample_visible        bool    true
//   eta | int_ior, ext_ior  float  polypropylene / air
#pragma once
#include "neepp/base/bsdf.h"
#include "neepp/base/texture.h"
#include "neepp/materials/microfacet.h"

namespace neepp {

class PolarizedPlasticBSDF final : public JointEvalBSDF {
public:
    // A null specular_reflectance means 1.
    PolarizedPlasticBSDF(MicrofacetType type, TexturePtr alpha_u, TexturePtr alpha_v, float eta,
                         TexturePtr diffuse_reflectance, TexturePtr specular_reflectance = nullptr,
                         bool sample_visible = true);
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFGlossyReflection | BSDFDiffuseReflection; }
    void prefetch(const SurfaceInteraction &si) const override {
        prefetch_textures(si, alpha_u_, alpha_v_, diffuse_reflectance_, specular_reflectance_);
    }
    bool needs_tangents() const override { return alpha_u_ != alpha_v_; }  // anisotropic: aligned with dp/du

private:
    MicrofacetDistribution distribution(const SurfaceInteraction &si) const;

    MicrofacetType type_;
    TexturePtr alpha_u_, alpha_v_;
    float eta_;
    TexturePtr diffuse_reflectance_, specular_reflectance_;
    bool sample_visible_;
    float specular_sampling_weight_;
};

}  // namespace neepp
