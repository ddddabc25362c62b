// Rough conductor (Mitsuba's `roughconductor`): one-sided microfacet reflection with complex-IOR Fresnel.
//
// Mitsuba XML parameters (default):
//   material              string  "none"      named preset (lookup_conductor_ior), as for `conductor`
//   eta, k                texture 0.0, 1.0    complex IOR when `eta` is given or material is "none"
//   distribution          string  "beckmann"  "beckmann" or "ggx" (parse_microfacet_type)
//   alpha                 texture 0.1         isotropic roughness; used for both alpha_u and alpha_v
//   alpha_u, alpha_v      texture  -          anisotropic roughness (both or neither; not with alpha)
//   sample_visible        bool    true        sample the distribution of visible normals
//   specular_reflectance  texture 1.0         multiplier (not physical)
#pragma once
#include "neepp/base/bsdf.h"
#include "neepp/materials/microfacet.h"

namespace neepp {

class RoughConductorBSDF final : public JointEvalBSDF {
public:
    // A null specular_reflectance means 1. For isotropic roughness pass the same texture twice.
    RoughConductorBSDF(MicrofacetType type, TexturePtr alpha_u, TexturePtr alpha_v, TexturePtr eta, TexturePtr k,
                       TexturePtr specular_reflectance = nullptr, bool sample_visible = true);
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFGlossyReflection; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, alpha_u_, alpha_v_, eta_, k_, specular_reflectance_); }
    bool needs_tangents() const override { return alpha_u_ != alpha_v_; }  // anisotropic: aligned with dp/du

private:
    MicrofacetDistribution distribution(const SurfaceInteraction &si) const;
    Color fresnel(const SurfaceInteraction &si, float cos_theta) const;

    MicrofacetType type_;
    TexturePtr alpha_u_, alpha_v_, eta_, k_, specular_reflectance_;
    bool sample_visible_;
};

}  // namespace neepp
