// Mitsuba 3's `principled` BSDF: Burley's Disney BSDF (2012 BRDF, 2015 specular transmission) as Mitsuba
// implements it, lobe for lobe, so that scenes render as they do there.
//
// Lobes, weighted by brdf = (1 - metallic)(1 - spec_trans) and bsdf = (1 - metallic) spec_trans:
//  - diffuse (front side): Burley's diffuse with retro-reflection, blended with the Hanrahan-Krueger "fake
//    subsurface" term by `flatness`; times brdf * base_color / pi. Sheen rides on it (only where brdf > 0):
//    sheen (1 - metallic) Schlick(cos theta_d) tinted by sheen_tint, without the 1/pi.
//  - main specular reflection (GGX, anisotropy mapped as Disney's notes): on the front side the Fresnel term
//    mixes the true dielectric Fresnel with Schlick's for the metal (F0 = base_color) and for the tinted
//    dielectric (F0 = tint * R0(eta)); seen from inside only the dielectric Fresnel, times bsdf.
//  - specular transmission (GGX, both sides): sqrt(base_color) * bsdf * the rough dielectric's transmission.
//  - clearcoat (front side): GTR1 normals with alpha from 0.1 to 0.001 by clearcoat_gloss, Schlick F0 = 0.04,
//    GGX shadowing at alpha 0.25, and, as in Mitsuba, without the 1/(4 cos_i cos_o) of a microfacet BRDF.
// Sampling picks diffuse, clearcoat, transmission or reflection with Mitsuba's probabilities (the
// sampling rates times the lobe weights, the dielectric Fresnel splitting the specular share); the
// weight is always eval over the whole mixture's density.
//
// Mitsuba XML parameters (default):
//   base_color        texture  0.5
//   roughness         texture  0.5
//   anisotropic, metallic, spec_trans, spec_tint, sheen, sheen_tint, flatness, clearcoat, clearcoat_gloss
//                     texture  0.0
//   eta               float    -     interior / exterior IOR (1 becomes 1.001 when spec_trans is given)
//   specular          float    0.5   the other way to give eta: eta = 2 / (1 - sqrt(0.08 specular)) - 1
//                                    (not both; 0 becomes 1e-3 when spec_trans is given)
//   main_specular_sampling_rate, clearcoat_sampling_rate, diffuse_reflectance_sampling_rate   float  1.0
#pragma once
#include <cmath>
#include "neepp/base/bsdf.h"
#include "neepp/materials/microfacet.h"

namespace neepp {

struct PrincipledParams {
    TexturePtr base_color, roughness;
    // Null when the scene does not give the parameter (or gives it as the float 0), Mitsuba's test for a
    // lobe's presence: a null parameter is 0, and a null spec_trans also means the BSDF has no
    // transmission lobe (flags, the eta adjustment).
    TexturePtr anisotropic, metallic, spec_trans, spec_tint, sheen, sheen_tint, flatness, clearcoat, clearcoat_gloss;
    float eta = 1.5f;
    float main_specular_sampling_rate = 1.f, clearcoat_sampling_rate = 1.f, diffuse_reflectance_sampling_rate = 1.f;
};

// Mitsuba's `specular` parameter as an IOR: the eta whose normal-incidence reflectance is 0.08 specular.
inline float principled_eta_from_specular(float specular) { return 2.f / (1.f - std::sqrt(0.08f * specular)) - 1.f; }

// The pieces that Mitsuba's principled and principledthin share.
namespace principled {
// Disney's roughness mapping: GGX with alpha = roughness^2, stretched along u and squeezed along v by the
// anisotropy (sqrt(1 - 0.9 anisotropic)), alpha at least 0.001.
MicrofacetDistribution distribution(float roughness, float anisotropic);
// Normal-incidence reflectance of an interface of relative IOR eta.
inline float schlick_r0(float eta) { return sqr((eta - 1.f) / (eta + 1.f)); }
// base_color divided by its luminance: its hue at unit brightness (white when black).
Color tint_color(const Color &base_color);
// Mitsuba's test that a microfacet normal m (pointing out of the surface) can carry wi to wo: both on
// m's front as seen from wi's side for a reflection, wo behind it for a refraction.
bool microfacet_compatible(const Vec3 &m, const Vec3 &wi, const Vec3 &wo, bool reflection);
// Burley's diffuse with retro-reflection, for |cos theta_i|, |cos theta_o| and cos theta_d = wh.wo, to be
// multiplied by base_color / pi; with `flatten`, blended by `flatness` toward Hanrahan-Krueger's "fake
// subsurface" term.
float diffuse_shape(float roughness, float abs_cos_i, float abs_cos_o, float cos_d, bool flatten, float flatness);
// The sheen's colour: white, or toward the base_color's hue by sheen_tint.
Color sheen_color(const Color &base_color, bool tinted, float sheen_tint);
}  // namespace principled

// Schlick's approximation of the Fresnel reflectance with normal-incidence reflectance r0, for light arriving
// at cosine cos_theta_i (negative: from inside) on an interface of relative IOR eta; arriving from the
// denser side it uses the refracted cosine (1 under total internal reflection), as Mitsuba's calc_schlick.
Color schlick_fresnel(const Color &r0, float cos_theta_i, float eta);
// (1 - cos)^5 clamped to [0, 1].
float schlick_weight(float cos_theta);

// Burley's GTR1 ("generalized Trowbridge-Reitz", gamma = 1) normal distribution, isotropic, for the
// clearcoat; sampled from D(m) cos(theta_m), not from visible normals.
class GTR1Distribution {
public:
    explicit GTR1Distribution(float alpha) : alpha_2_(alpha * alpha) {}
    float eval(const Vec3 &m) const;
    float pdf(const Vec3 &m) const { return m.z < 0.f ? 0.f : m.z * eval(m); }
    Vec3 sample(Vec2 u) const;

private:
    float alpha_2_;
};

class PrincipledBSDF final : public JointEvalBSDF {
public:
    explicit PrincipledBSDF(PrincipledParams p);
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return flags_; }
    void prefetch(const SurfaceInteraction &si) const override;
    bool needs_tangents() const override { return p_.anisotropic != nullptr; }
    float eta() const { return p_.eta; }

    // The parameters looked up at a hit.
    struct Local {
        Color base_color;
        float roughness, anisotropic, metallic, spec_trans, spec_tint, sheen, sheen_tint, flatness, clearcoat,
            clearcoat_gloss;
        float brdf() const { return (1.f - metallic) * (1.f - spec_trans); }
        float bsdf() const { return (1.f - metallic) * spec_trans; }
    };

private:
    Local lookup(const SurfaceInteraction &si) const;
    MicrofacetDistribution specular_distribution(const Local &l) const;
    // Probabilities of choosing diffuse, clearcoat, specular transmission and specular reflection, given
    // the dielectric Fresnel reflectance at the specular lobes' microfacet normal.
    struct LobeProbabilities {
        float diffuse = 0, clearcoat = 0, transmission = 0, reflection = 0;
    };
    LobeProbabilities lobe_probabilities(const Local &l, bool front_side, float fresnel) const;

    PrincipledParams p_;
    uint32_t flags_;
};

}  // namespace neepp
