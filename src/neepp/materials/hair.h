// Hair fibre (Mitsuba 3's `hair`): the near-field model of Chiang et al. 2016, "A Practical and
// Controllable Hair and Fur Model for Production Path Tracing". One scattering event stands for the whole
// walk through the fibre, entered and left at the same point: reflection (R, p = 0), transmission (TT,
// p = 1), one internal reflection (TRT, p = 2) and all longer walks summed into one lobe (p = 3). Each of
// the first three is d'Eon et al.'s longitudinal lobe around the cone tilted by the cuticle scales, times
// a trimmed logistic in azimuth around the perfect-specular exit; the rest is longitudinal only.
//
// The fibre's frame is the shading frame as Mitsuba builds it for its curves: the fibre runs along t
// (local y), the normal n is local z, and s (local x) follows dp/du round the fibre. The longitudinal
// angle theta is measured from the plane normal to the fibre (sin theta = w.y), the azimuth is
// phi = atan2(w.z, w.x), and the offset across the fibre comes from wi alone: h = sin(gamma_i), gamma_i
// the angle from the normal to wi's projection on that plane. On any other shape the fibre runs along
// n x dp/du, as in Mitsuba: a cylinder's axis (its u goes round it), a sphere's meridians.
//
// Mitsuba XML parameters (default):
//   eumelanin, pheomelanin  float          1.3, 0.2  pigment concentrations, giving sigma_a (below)
//   sigma_a                 texture        -         absorption per unit of fibre radius, instead of pigments
//   scale                   float          1         multiplies sigma_a (not the pigments' absorption)
//   int_ior, ext_ior        float/string   amber (1.55), air
//   longitudinal_roughness  float          0.3       beta_m, in (0, 1]
//   azimuthal_roughness     float          0.3       beta_n, in (0, 1]
//   scale_tilt              float          2         the cuticle scales' tilt alpha, in degrees
// Mitsuba has no reflectance-to-absorption inversion (pbrt's `reflectance`), so neither has this.
//
// Radiance transport uses the model as Mitsuba evaluates it, with wi toward the viewer. The model is not
// reciprocal (h follows wi, and the scales tilt each lobe one way), so importance transport (light
// paths) carries its adjoint f(wo, wi), which Mitsuba does not: light tracing and BDPT then converge to
// what path tracing renders.
#pragma once
#include <utility>

#include "neepp/base/bsdf.h"

namespace neepp {

// Absorption per fibre radius of the two melanins at these concentrations (d'Eon et al. 2011's
// coefficients, as Mitsuba's RGB variants use them).
Color hair_pigment_absorption(float eumelanin, float pheomelanin);

struct HairParams {
    float longitudinal_roughness = 0.3f;  // beta_m
    float azimuthal_roughness = 0.3f;     // beta_n
    float scale_tilt_deg = 2.f;           // alpha
    float eta = 1.55f / 1.000277f;        // interior / exterior
    TexturePtr sigma_a;                   // absorption per fibre radius; negative values count as 0
    float sigma_a_scale = 1.f;
};

class HairBSDF final : public JointEvalBSDF {
public:
    // Throws std::invalid_argument for roughness outside (0, 1], a non-finite tilt, or eta 1 or below 0.
    explicit HairBSDF(HairParams params);
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return BSDFGlossy; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, p_.sigma_a); }
    // The fibre runs along n x dp/du: a frame built from the normal alone would turn it arbitrarily.
    bool needs_tangents() const override { return true; }

    static constexpr int kLobes = 4;  // R, TT, TRT and the sum of the longer walks

    // What the incident direction fixes, shared by every outgoing direction: its angles, the refracted
    // azimuth inside the fibre and each lobe's attenuation and sampling probability.
    struct Incidence {
        float sin_theta = 0, cos_theta = 1, phi = 0, gamma = 0, gamma_t = 0;
        Color attenuation[kLobes];
        float lobe_pdf[kLobes] = {};
    };
    Incidence incidence(const SurfaceInteraction &si, const Vec3 &wi) const;

private:
    // f·|cos θo| (radiance transport) and the density of sampling wo, for the incidence `in`.
    BSDFEval scatter(const Incidence &in, const Vec3 &wo) const;
    // sin and |cos| of the incident longitudinal angle as lobe p sees it (tilted by the scales for p < 3).
    std::pair<float, float> tilted(const Incidence &in, int p) const;
    // The trimmed logistic of lobe p < 3 at azimuth difference dphi = phi_o - phi_i.
    float azimuthal(const Incidence &in, int p, float dphi) const;
    // Importance transport's value: the radiance one with the directions swapped (the adjoint).
    Color adjoint(const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const;

    HairParams p_;
    float v_[kLobes];                         // longitudinal variances
    float s_;                                 // logistic scale of the azimuthal lobes
    float tilt_sin_[kLobes - 1], tilt_cos_[kLobes - 1];  // the scales' shift of R, TT, TRT: -2a, a, 4a
};

}  // namespace neepp
