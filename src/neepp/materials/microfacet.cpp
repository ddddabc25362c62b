#include "neepp/materials/microfacet.h"

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "neepp/materials/fresnel.h"
#include "neepp/math/frame.h"
#include "neepp/math/warp.h"

namespace neepp {

std::optional<MicrofacetType> parse_microfacet_type(std::string_view name) {
    std::string lower(name);
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    if (lower == "beckmann") return MicrofacetType::Beckmann;
    if (lower == "ggx") return MicrofacetType::GGX;
    return std::nullopt;
}

MicrofacetDistribution::MicrofacetDistribution(MicrofacetType type, float alpha_u, float alpha_v,
                                               bool sample_visible)
    : type_(type), alpha_u_(std::max(alpha_u, 1e-4f)), alpha_v_(std::max(alpha_v, 1e-4f)),
      sample_visible_(sample_visible) {}

float MicrofacetDistribution::eval(const Vec3 &m) const {
    float cos2 = m.z * m.z, x = m.x / alpha_u_, y = m.y / alpha_v_, result;
    if (type_ == MicrofacetType::Beckmann)
        result = std::exp(-(x * x + y * y) / cos2) / (kPi * alpha_u_ * alpha_v_ * cos2 * cos2);
    else
        result = 1.f / (kPi * alpha_u_ * alpha_v_ * sqr(x * x + y * y + cos2));
    // Mitsuba zeroes vanishing values (and the lower hemisphere) to keep later stages finite.
    return result * m.z > 1e-20f ? result : 0.f;
}

float MicrofacetDistribution::pdf(const Vec3 &wi, const Vec3 &m) const {
    float result = eval(m);
    if (sample_visible_) return result * smith_g1(wi, m) * absdot(wi, m) / wi.z;
    return result * m.z;
}

float MicrofacetDistribution::smith_g1(const Vec3 &v, const Vec3 &m) const {
    float xy_alpha_2 = sqr(alpha_u_ * v.x) + sqr(alpha_v_ * v.y);
    float tan_theta_alpha_2 = xy_alpha_2 / (v.z * v.z), result;
    if (type_ == MicrofacetType::Beckmann) {
        // Mitsuba's rational fit of the Beckmann shadowing term (< 0.35% relative error).
        float a = 1.f / std::sqrt(tan_theta_alpha_2), a2 = a * a;
        result = a >= 1.6f ? 1.f : (3.535f * a + 2.181f * a2) / (1.f + 2.276f * a + 2.577f * a2);
    } else {
        result = 2.f / (1.f + std::sqrt(1.f + tan_theta_alpha_2));
    }
    if (xy_alpha_2 == 0.f) result = 1.f;  // normal incidence: nothing is shadowed
    // The back of a microfacet is never visible from the front of the macrosurface, and vice versa.
    if (dot(v, m) * v.z <= 0.f) result = 0.f;
    return result;
}

std::pair<Vec3, float> MicrofacetDistribution::sample(const Vec3 &wi, Vec2 u) const {
    if (!sample_visible_) return sample_projected_area(u);
    const Vec3 m = sample_visible_normal(wi, u);
    return {m, eval(m) * smith_g1(wi, m) * absdot(wi, m) / wi.z};
}

Vec3 MicrofacetDistribution::sample_normal(const Vec3 &wi, Vec2 u) const {
    // Without visible normals the density comes with the sample, at no cost.
    return sample_visible_ ? sample_visible_normal(wi, u) : sample_projected_area(u).first;
}

std::pair<Vec3, float> MicrofacetDistribution::sample_projected_area(Vec2 u) const {
    // Sample D(m) cos(theta_m): azimuth first (shared by both distributions), then elevation.
    float sin_phi, cos_phi, alpha_2;
    if (alpha_u_ == alpha_v_) {
        const SinCos phi = sincos_turns(u.y);
        sin_phi = phi.sin;
        cos_phi = phi.cos;
        alpha_2 = alpha_u_ * alpha_u_;
    } else {
        float ratio = alpha_v_ / alpha_u_, tmp = ratio * std::tan(2.f * kPi * u.y);
        cos_phi = std::copysign(1.f / std::sqrt(tmp * tmp + 1.f), std::abs(u.y - .5f) - .25f);
        sin_phi = cos_phi * tmp;
        alpha_2 = 1.f / (sqr(cos_phi / alpha_u_) + sqr(sin_phi / alpha_v_));
    }
    float cos_theta, pdf;
    if (type_ == MicrofacetType::Beckmann) {
        cos_theta = 1.f / std::sqrt(1.f - alpha_2 * std::log(1.f - u.x));
        float cos3 = std::max(cos_theta * cos_theta * cos_theta, 1e-20f);
        pdf = (1.f - u.x) / (kPi * alpha_u_ * alpha_v_ * cos3);
    } else {
        float tan_theta_m_2 = alpha_2 * u.x / (1.f - u.x);
        cos_theta = 1.f / std::sqrt(1.f + tan_theta_m_2);
        float temp = 1.f + tan_theta_m_2 / alpha_2;
        float cos3 = std::max(cos_theta * cos_theta * cos_theta, 1e-20f);
        pdf = 1.f / (kPi * alpha_u_ * alpha_v_ * cos3 * temp * temp);
    }
    float sin_theta = std::sqrt(1.f - cos_theta * cos_theta);
    return {Vec3(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta), pdf};
}

Vec3 MicrofacetDistribution::sample_visible_normal(const Vec3 &wi, Vec2 u) const {
    // Visible normals (Heitz and d'Eon 2014): stretch wi to the alpha = 1 configuration, sample slopes
    // there, rotate back to wi's azimuth and unstretch.
    Vec3 wi_p = normalize(Vec3(alpha_u_ * wi.x, alpha_v_ * wi.y, wi.z));
    float sin_theta_2 = wi_p.x * wi_p.x + wi_p.y * wi_p.y, sin_phi = 0.f, cos_phi = 1.f;
    if (std::abs(sin_theta_2) > 4.f * 0x1p-24f) {
        float inv_sin_theta = 1.f / std::sqrt(sin_theta_2);
        cos_phi = std::clamp(wi_p.x * inv_sin_theta, -1.f, 1.f);
        sin_phi = std::clamp(wi_p.y * inv_sin_theta, -1.f, 1.f);
    }
    Vec2 slope = sample_visible_11(wi_p.z, u);
    slope = Vec2((cos_phi * slope.x - sin_phi * slope.y) * alpha_u_,
                 (sin_phi * slope.x + cos_phi * slope.y) * alpha_v_);
    return normalize(Vec3(-slope.x, -slope.y, 1.f));
}

Vec2 MicrofacetDistribution::sample_visible_11(float cos_theta_i, Vec2 u) const {
    if (type_ == MicrofacetType::Beckmann) {
        // Numerical inversion of the visible-slope CDF in the erf() domain (Mitsuba's variant of Heitz and
        // d'Eon, continuous in the sample so it behaves with QMC and MLT).
        float tan_theta_i = safe_sqrt(1.f - cos_theta_i * cos_theta_i) / cos_theta_i;
        float cot_theta_i = 1.f / tan_theta_i;
        float maxval = std::erf(cot_theta_i);
        u = Vec2(std::clamp(u.x, 1e-6f, 1.f - 1e-6f), std::clamp(u.y, 1e-6f, 1.f - 1e-6f));
        // Initial guess: the analytic solution for theta_i = pi/2, the most nonlinear case.
        float x = maxval - (maxval + 1.f) * std::erf(std::sqrt(-std::log(u.x)));
        constexpr float kInvSqrtPi = 0.56418958354775628695f;
        float target = u.x * (1.f + maxval + kInvSqrtPi * tan_theta_i * std::exp(-cot_theta_i * cot_theta_i));
        for (int i = 0; i < 3; ++i) {  // Newton
            float slope = erfinv(x);
            float value = 1.f + x + kInvSqrtPi * tan_theta_i * std::exp(-slope * slope) - target;
            float derivative = 1.f - slope * tan_theta_i;
            x -= value / derivative;
        }
        return {erfinv(x), erfinv(2.f * u.y - 1.f)};
    }
    // GGX: sample the projected hemisphere (Heitz 2018 style), then convert the point to a slope.
    Vec2 p = square_to_uniform_disk_concentric(u);
    float s = 0.5f * (1.f + cos_theta_i);
    float lo = safe_sqrt(1.f - p.x * p.x);
    p.y = lo + (p.y - lo) * s;
    float x = p.x, y = p.y, z = safe_sqrt(1.f - x * x - y * y);
    float sin_theta_i = safe_sqrt(1.f - cos_theta_i * cos_theta_i);
    float inv_norm = 1.f / (sin_theta_i * y + cos_theta_i * z);
    return {(cos_theta_i * y - sin_theta_i * z) * inv_norm, x * inv_norm};
}

float erfinv(float x) {
    float w = -std::log((1.f - x) * (1.f + x)), p;
    if (w < 5.f) {
        w -= 2.5f;
        p = 2.81022636e-08f;
        p = 3.43273939e-07f + p * w;
        p = -3.5233877e-06f + p * w;
        p = -4.39150654e-06f + p * w;
        p = 0.00021858087f + p * w;
        p = -0.00125372503f + p * w;
        p = -0.00417768164f + p * w;
        p = 0.246640727f + p * w;
        p = 1.50140941f + p * w;
    } else {
        w = std::sqrt(w) - 3.f;
        p = -0.000200214257f;
        p = 0.000100950558f + p * w;
        p = 0.00134934322f + p * w;
        p = -0.00367342844f + p * w;
        p = 0.00573950773f + p * w;
        p = -0.0076224613f + p * w;
        p = 0.00943887047f + p * w;
        p = 1.00167406f + p * w;
        p = 2.83297682f + p * w;
    }
    return p * x;
}

namespace {

// Gauss-Legendre nodes and weights on [-1, 1] (Newton iteration on the Legendre recurrence).
struct Quadrature {
    std::vector<float> nodes, weights;
};

// P_n(x) by the three-term recurrence, and its derivative from P_n and P_{n-1}.
struct Legendre {
    double value, derivative;
};
Legendre legendre(int n, double x) {
    double p0 = 1, p1 = x;
    for (int k = 2; k <= n; ++k) {
        double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    return {p1, n * (x * p1 - p0) / (x * x - 1.0)};
}

Quadrature gauss_legendre(int n) {
    Quadrature q;
    q.nodes.resize(n);
    q.weights.resize(n);
    for (int i = 0; i < n; ++i) {
        double x = -std::cos((2.0 * i + 1.0) / (2.0 * n) * 3.14159265358979323846);
        for (int it = 0; it < 100; ++it) {
            const Legendre p = legendre(n, x);
            double step = p.value / p.derivative;
            x -= step;
            if (std::abs(step) < 1e-15) break;
        }
        // The derivative at the converged node.
        const double dp = legendre(n, x).derivative;
        q.nodes[i] = float(x);
        q.weights[i] = float(2.0 / ((1.0 - x * x) * dp * dp));
    }
    return q;
}

const Quadrature &cached_gauss_legendre(int n) {
    static const Quadrature q32 = gauss_legendre(32), q128 = gauss_legendre(128);
    return n == 32 ? q32 : q128;
}

// Integrates over the visible-normal sample square; `term(m)` is the per-microfacet contribution.
// With an isotropic distribution and wi in the xz-plane (the tables' case), mirroring one coordinate of the
// sample square, u -> 1 - u, mirrors the sampled normal across that plane (m.y -> -m.y): the coordinate
// GGX's concentric disk maps to the slope's y (u.x), or Beckmann's second inversion (u.y). The terms are
// the same for m and its mirror image (wo mirrors, and Fresnel and G1 see only dot(wi, m), v.y^2 and z),
// and the Gauss-Legendre nodes are symmetric, so half the nodes of that axis, counted twice, give the
// same sum up to rounding at half the cost (rough plastic's tables: 2 x 64 quadratures of 128^2 nodes).
template <typename Term>
float integrate_visible_normals(const MicrofacetDistribution &distr, const Vec3 &wi, float eta, Term term) {
    const Quadrature &q = cached_gauss_legendre(eta > 1.f ? 32 : 128);
    const int n = int(q.nodes.size());
    const bool mirrored = distr.alpha_u() == distr.alpha_v() && wi.y == 0.f;
    const bool mirror_x = distr.type() == MicrofacetType::GGX;
    const int ni = mirrored && mirror_x ? n / 2 : n, nj = mirrored && !mirror_x ? n / 2 : n;
    // 0.25: the weights are for [-1, 1]^2, the sample square is [0, 1]^2.
    const float scale = mirrored ? 0.5f : 0.25f;
    float result = 0.f;
    for (int j = 0; j < nj; ++j)
        for (int i = 0; i < ni; ++i) {
            Vec2 node(q.nodes[i] * 0.5f + 0.5f, q.nodes[j] * 0.5f + 0.5f);
            Vec3 m = distr.sample_normal(wi, node);
            result += term(m) * (q.weights[i] * q.weights[j]) * scale;
        }
    return result;
}

}  // namespace

float eval_reflectance(const MicrofacetDistribution &distr, const Vec3 &wi, float eta) {
    return integrate_visible_normals(distr, wi, eta, [&](const Vec3 &m) {
        Vec3 wo = reflect(wi, m);
        if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
        return distr.smith_g1(wo, m) * fresnel_dielectric(dot(wi, m), eta).r;
    });
}

float eval_transmittance(const MicrofacetDistribution &distr, const Vec3 &wi, float eta) {
    return integrate_visible_normals(distr, wi, eta, [&](const Vec3 &m) {
        FresnelResult f = fresnel_dielectric(dot(wi, m), eta);
        Vec3 wo = refract(wi, m, f.cos_theta_t, f.eta_ti);
        if (wo.z * wi.z >= 0.f) return 0.f;
        return distr.smith_g1(wo, m) * (1.f - f.r);
    });
}

}  // namespace neepp
