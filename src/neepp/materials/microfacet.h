// Microfacet normal distributions (Beckmann, GGX) with Smith shadowing and visible-normal sampling,
// following Mitsuba 3's render/microfacet.h so rough BSDFs sample and evaluate exactly as Mitsuba's.
#pragma once
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

// Directional albedo of a rough dielectric interface seen from wi (Mitsuba's eval_reflectance /
// eval_transmittance): single-scattering reflection resp. transmission, integrated with Gauss-Legendre
// quadrature over the visible-normal sample space. `distr` must sample visible normals.
float eval_reflectance(const MicrofacetDistribution &distr, const Vec3 &wi, float eta);
float eval_transmittance(const MicrofacetDistribution &distr, const Vec3 &wi, float eta);

// Inverse error function (Giles' single-precision approximation, as Dr.Jit uses).
float erfinv(float x);

}  // namespace neepp
