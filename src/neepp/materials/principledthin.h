// Mitsuba 3's `principledthin` BSDF: Burley's 2015 thin-surface BSDF as Mitsuba implements it, for
// surfaces without volume (leaves, paper, cloth): two-sided (seen from behind it is the same BSDF
// mirrored), no refraction (relative IOR 1 across it), so importance and radiance transport agree.
//
// Lobes, with spec_trans the share of the specular pair and diff_trans / 2 that of the diffuse
// transmission within the rest:
//  - specular reflection (only where spec_trans > 0): spec_trans * F * D G / (4 cos_i), GGX with Disney's
//    roughness mapping, F the dielectric Fresnel of eta lerped toward Schlick's of the tinted base_color
//    by spec_tint;
//  - specular transmission: spec_trans * base_color * (1 - F) * D' G' / (4 cos_i), the reflection mirrored
//    through the surface, D' of roughness scaled by 0.65 eta - 0.35 (Burley 2015, figure 15);
//  - diffuse reflection: (1 - spec_trans)(1 - diff_trans/2) times principled's Burley diffuse (flatness
//    included) and sheen (no metallic here);
//  - diffuse transmission: (1 - spec_trans) diff_trans/2 base_color / pi.
// Sampling picks the lobes with Mitsuba's probabilities (spec_trans/2 for each specular lobe, the
// diffuse ones by their weights, times the sampling rates); the weight is eval over the mixture density.
//
// Mitsuba XML parameters (default):
//   base_color, roughness   texture  0.5
//   anisotropic, spec_trans, spec_tint, sheen, sheen_tint, flatness   texture  0.0
//   diff_trans              texture  0.0   in [0, 2]
//   eta                     texture  1.5   relative IOR of the thin sheet
//   specular_reflectance_sampling_rate, specular_transmittance_sampling_rate,
//   diffuse_reflectance_sampling_rate, diffuse_transmittance_sampling_rate   float  1.0
#pragma once
#include "neepp/base/bsdf.h"
#include "neepp/materials/microfacet.h"

namespace neepp {

struct PrincipledThinParams {
    TexturePtr base_color, roughness, eta;
    // Null when left out (or given as the float 0): the lobe is off, as Mitsuba's presence test.
    TexturePtr anisotropic, spec_trans, spec_tint, sheen, sheen_tint, flatness, diff_trans;
    float specular_reflectance_sampling_rate = 1.f, specular_transmittance_sampling_rate = 1.f,
          diffuse_reflectance_sampling_rate = 1.f, diffuse_transmittance_sampling_rate = 1.f;
};

class PrincipledThinBSDF final : public JointEvalBSDF {
public:
    explicit PrincipledThinBSDF(PrincipledThinParams p);
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return flags_; }
    void prefetch(const SurfaceInteraction &si) const override;
    bool needs_tangents() const override { return p_.anisotropic != nullptr; }

    struct Local {
        Color base_color;
        float roughness, anisotropic, spec_trans, spec_tint, sheen, sheen_tint, flatness, diff_trans, eta;
    };

private:
    Local lookup(const SurfaceInteraction &si) const;
    // The roughness of the transmission lobe's normals.
    float transmission_roughness(const Local &l) const { return (0.65f * l.eta - 0.35f) * l.roughness; }
    struct LobeProbabilities {
        float spec_reflection = 0, spec_transmission = 0, diffuse_reflection = 0, diffuse_transmission = 0;
    };
    LobeProbabilities lobe_probabilities(const Local &l) const;

    PrincipledThinParams p_;
    uint32_t flags_;
};

}  // namespace neepp
