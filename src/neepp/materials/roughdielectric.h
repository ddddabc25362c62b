// Rough dielectric (Mitsuba's `roughdielectric`): microfacet reflection and refraction at a rough interface
// between two dielectrics (Walter et al. 2007), two-sided. A microfacet normal is drawn (visible normals by
// default) and the Fresnel reflectance at it chooses reflection or refraction. Refraction scales radiance
// by 1/eta^2 (eta along the direction of travel) in TransportMode::Radiance only.
//
// As Mitsuba, without visible-normal sampling the normals are drawn from D(m) cos(theta_m) of a roughness
// widened by 1.2 - 0.2 sqrt(|cos theta_i|) (Walter's trick), and the sample weight is
// G(wi, wo) |wi.m| / (|cos theta_i| cos theta_m) times the multiplier, which is eval / pdf only for the
// unwidened distribution: that variant's weights are Mitsuba's, not eval / pdf. pdf() is the density of
// sample(), widened distribution included.
//
// Mitsuba XML parameters (default):
//   int_ior                 float or IOR name  "bk7" (1.5046)   interior IOR (lookup_dielectric_ior)
//   ext_ior                 float or IOR name  "air" (1.000277) exterior IOR (must differ from int_ior)
//   distribution            string   "beckmann"  "beckmann" or "ggx" (parse_microfacet_type)
//   alpha                   texture  0.1         isotropic roughness; used for both alpha_u and alpha_v
//   alpha_u, alpha_v        texture  -           anisotropic roughness (both or neither; not with alpha)
//   sample_visible          bool     true        sample the distribution of visible normals
//   specular_reflectance    texture  1.0         multiplier (not physical)
//   specular_transmittance  texture  1.0         multiplier (not physical)
#pragma once
#include "neepp/base/bsdf.h"
#include "neepp/materials/microfacet.h"

namespace neepp {

class RoughDielectricBSDF final : public JointEvalBSDF {
public:
    // Null multipliers mean 1. For isotropic roughness pass the same texture twice. Throws
    // std::invalid_argument when the IORs are not positive or are equal (Mitsuba's check).
    RoughDielectricBSDF(MicrofacetType type, TexturePtr alpha_u, TexturePtr alpha_v, float int_ior, float ext_ior,
                        TexturePtr specular_reflectance = nullptr, TexturePtr specular_transmittance = nullptr,
                        bool sample_visible = true);
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFGlossyReflection | BSDFGlossyTransmission; }
    void prefetch(const SurfaceInteraction &si) const override {
        prefetch_textures(si, alpha_u_, alpha_v_, specular_reflectance_, specular_transmittance_);
    }
    bool needs_tangents() const override { return alpha_u_ != alpha_v_; }  // anisotropic: aligned with dp/du
    float eta() const { return eta_; }

private:
    MicrofacetDistribution distribution(const SurfaceInteraction &si) const;
    // The distribution that sample() draws normals from, seen from wi.
    MicrofacetDistribution sampling_distribution(const MicrofacetDistribution &distr, float cos_theta_i) const;

    MicrofacetType type_;
    TexturePtr alpha_u_, alpha_v_;
    float eta_, inv_eta_;
    TexturePtr specular_reflectance_, specular_transmittance_;  // null: 1
    bool sample_visible_;
};

}  // namespace neepp
