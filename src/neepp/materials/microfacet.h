// Microfacet normal distributions (Beckmann, GGX) with Smith shadowing and visible-normal sampling,
// following Mitsuba 3's render/microfacet.h so rough BSDFs sample and evaluate exactly as Mitsuba's.
#pragma once
#include <cmath>
#include <optional>
#include <string_view>
#include <utility>
#include "neepp/math/vec.h"

namespace neepp {

enum class MicrofacetType { Beckmann, GGX };

// "beckmann" / "ggx" (case-insensitive), the values of Mitsuba's `distribution` parameter.
std::optional<MicrofacetType> parse_microfacet_type(std::string_view name);

class MicrofacetDistribution {
public:
    // Roughness is clamped to 1e-4 like Mitsuba: a zero alpha would make D a Dirac.
    MicrofacetDistribution(MicrofacetType type, float alpha_u, float alpha_v, bool sample_visible = true);
    MicrofacetDistribution(MicrofacetType type, float alpha, bool sample_visible = true)
        : MicrofacetDistribution(type, alpha, alpha, sample_visible) {}

    MicrofacetType type() const { return type_; }
    float alpha_u() const { return alpha_u_; }
    float alpha_v() const { return alpha_v_; }
    bool sample_visible() const { return sample_visible_; }

    // Microfacet normal density D(m), projected-area normalized (integral of D(m) cos(theta_m) dm = 1).
    float eval(const Vec3 &m) const;
    // Density of sample(wi, .) producing m: D_wi(m) if visible normals are sampled, else D(m) cos(theta_m).
    float pdf(const Vec3 &wi, const Vec3 &m) const;
    // Density of the direction wo = reflect(wi, h) when h is drawn by sample(wi, .), given D(h) and G1(wi, h)
    // already computed for the BSDF's value (both plastics' specular lobes).
    float reflection_pdf(const Vec3 &wi, const Vec3 &wo, const Vec3 &h, float d, float g1_i) const {
        return sample_visible_ ? d * g1_i / (4.f * wi.z) : pdf(wi, h) / (4.f * dot(wo, h));
    }
    // Samples a microfacet normal; returns it with its density pdf(wi, m).
    std::pair<Vec3, float> sample(const Vec3 &wi, Vec2 u) const;
    // The same normal without its density, for callers that evaluate a mixture's density themselves
    // (rough plastic, the albedo quadrature): D and G1 are then not computed twice.
    Vec3 sample_normal(const Vec3 &wi, Vec2 u) const;
    // Smith's separable shadowing-masking G1(wi) G1(wo).
    float G(const Vec3 &wi, const Vec3 &wo, const Vec3 &m) const { return smith_g1(wi, m) * smith_g1(wo, m); }
    float smith_g1(const Vec3 &v, const Vec3 &m) const;

private:
    // D(m) cos(theta_m) sampled, with its density; visible normals D_wi(m) sampled (density not computed).
    std::pair<Vec3, float> sample_projected_area(Vec2 u) const;
    Vec3 sample_visible_normal(const Vec3 &wi, Vec2 u) const;
    Vec2 sample_visible_11(float cos_theta_i, Vec2 u) const;

    MicrofacetType type_;
    float alpha_u_, alpha_v_;
    bool sample_visible_;
};

// The geometry of a rough dielectric interface (Walter et al. 2007), shared by Mitsuba's roughdielectric
// and principled's transmission lobe. eta_path is the relative IOR seen from wi's side (eta from outside,
// 1 / eta from inside); reflect says whether wo is on wi's side.
// The generalized half vector of wi and wo, turned into the upper hemisphere.
inline Vec3 dielectric_half_vector(const Vec3 &wi, const Vec3 &wo, bool reflect, float eta_path) {
    const Vec3 m = normalize(wi + wo * (reflect ? 1.f : eta_path));
    return m.z < 0.f ? -m : m;
}
// |d m / d wo|, the Jacobian that turns a density of microfacet normals into one of directions.
inline float dielectric_half_vector_jacobian(float wi_m, float wo_m, bool reflect, float eta_path) {
    return std::abs(reflect ? 1.f / (4.f * wo_m) : sqr(eta_path) * wo_m / sqr(wi_m + eta_path * wo_m));
}
// f |cos theta_o| of microfacet transmission, given the dielectric Fresnel reflectance, D and G at the half
// vector m, wi.m, wo.m and cos theta_i. Radiance is compressed by 1 / eta_path^2 as it crosses the
// interface; importance (radiance = false) is not.
inline float dielectric_microfacet_transmission(float fresnel, float d, float g, float wi_m, float wo_m, float cos_i,
                                                float eta_path, bool radiance) {
    const float scale = radiance ? 1.f / sqr(eta_path) : 1.f;
    return std::abs(scale * (1.f - fresnel) * d * g * sqr(eta_path) * wi_m * wo_m /
                    (cos_i * sqr(wi_m + eta_path * wo_m)));
}

// Directional albedo of a rough dielectric interface seen from wi (Mitsuba's eval_reflectance /
// eval_transmittance): single-scattering reflection resp. transmission, integrated with Gauss-Legendre
// quadrature over the visible-normal sample space. `distr` must sample visible normals.
float eval_reflectance(const MicrofacetDistribution &distr, const Vec3 &wi, float eta);
float eval_transmittance(const MicrofacetDistribution &distr, const Vec3 &wi, float eta);

// Inverse error function (Giles' single-precision approximation, as Dr.Jit uses).
float erfinv(float x);

}  // namespace neepp
