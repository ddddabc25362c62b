#include "neepp/materials/hair.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "neepp/materials/fresnel.h"

namespace neepp {
namespace {

// log(I0(x)) - x for x >= 0, I0 the modified Bessel function of the first kind: the power series below 12,
// above it the asymptotic expansion e^x / sqrt(2 pi x) (1 + 1/(8x) + 9/(128x^2) + 225/(3072x^3)), whose
// next term is below 6e-6 there. Without the x, the longitudinal lobe's exponent has no large terms to
// cancel, so narrow lobes stay exact.
float log_i0_minus_x(float x) {
    if (x > 12.f) {
        const float r = 1.f / x;
        return -0.5f * std::log(2.f * kPi * x) + std::log1p(r * (0.125f + r * (0.0703125f + r * 0.0732421875f)));
    }
    // sum over k of (x^2/4)^k / (k!)^2; at x = 12 the terms fall below float precision by k = 24.
    const float q = 0.25f * x * x;
    float term = 1.f, sum = 1.f;
    for (int k = 1; k < 26 && term > 1e-8f * sum; ++k) {
        term *= q / float(k * k);
        sum += term;
    }
    return std::log(sum) - x;
}

// d'Eon et al. 2011's longitudinal lobe with variance v, from incident angle theta_i to outgoing theta_o:
// a density over theta_o with respect to cos(theta_o) dtheta_o, peaked on the specular cone theta_o =
// -theta_i. With kappa = 1/v it is kappa / (2 sinh kappa) exp(-kappa sin_i sin_o) I0(kappa cos_i cos_o),
// rewritten as kappa / (1 - e^(-2 kappa)) exp(-kappa (1 - cos(theta_i + theta_o))) I0(a) e^(-a).
float longitudinal(float sin_i, float cos_i, float sin_o, float cos_o, float v) {
    const float kappa = 1.f / v;
    // 1 - cos(theta_i + theta_o), as half the squared distance between (cos_i, sin_i) and (cos_o, -sin_o):
    // no cancellation near the cone.
    const float off_cone = 0.5f * (sqr(cos_i - cos_o) + sqr(sin_i + sin_o));
    return std::exp(-kappa * off_cone + log_i0_minus_x(kappa * cos_i * cos_o)) * kappa / -std::expm1(-2.f * kappa);
}

float logistic(float x, float s) {
    const float e = std::exp(-std::abs(x) / s);
    return e / (s * sqr(1.f + e));
}

float logistic_cdf(float x, float s) { return 1.f / (1.f + std::exp(-x / s)); }

// The logistic distribution of scale s restricted to [-pi, pi] (Chiang et al.'s azimuthal roughness).
float trimmed_logistic(float x, float s) {
    return logistic(x, s) / (logistic_cdf(kPi, s) - logistic_cdf(-kPi, s));
}

float sample_trimmed_logistic(float u, float s) {
    const float lo = logistic_cdf(-kPi, s), k = logistic_cdf(kPi, s) - lo;
    return std::clamp(-s * std::log(1.f / (u * k + lo) - 1.f), -kPi, kPi);
}

// The azimuth difference at which a perfectly smooth fibre sends lobe p < 3: reflected about the normal,
// then turned by each crossing.
float specular_exit(const HairBSDF::Incidence &in, int p) { return 2.f * p * in.gamma_t - 2.f * in.gamma + p * kPi; }

}  // namespace

Color hair_pigment_absorption(float eumelanin, float pheomelanin) {
    return Color(0.419f, 0.697f, 1.37f) * eumelanin + Color(0.187f, 0.4f, 1.05f) * pheomelanin;
}

HairBSDF::HairBSDF(HairParams params) : p_(std::move(params)) {
    const float bm = p_.longitudinal_roughness, bn = p_.azimuthal_roughness;
    // Mitsuba accepts 0, where the model has no density (its fibre then renders black, or with the
    // longer walks alone).
    if (!(bm > 0.f && bm <= 1.f)) throw std::invalid_argument("'longitudinal_roughness' must be in (0, 1]");
    if (!(bn > 0.f && bn <= 1.f)) throw std::invalid_argument("'azimuthal_roughness' must be in (0, 1]");
    if (!std::isfinite(p_.scale_tilt_deg)) throw std::invalid_argument("'scale_tilt' must be finite");
    if (!(p_.eta > 0.f) || p_.eta == 1.f || !std::isfinite(p_.eta))
        throw std::invalid_argument("the interior and exterior indices of refraction must be positive and differ");
    if (!(p_.sigma_a_scale >= 0.f) || !std::isfinite(p_.sigma_a_scale))
        throw std::invalid_argument("'scale' must be non-negative and finite");
    if (!p_.sigma_a) p_.sigma_a = constant_texture(hair_pigment_absorption(1.3f, 0.2f));

    // Chiang et al.'s fits of the lobe widths to their path-traced fibre: the longitudinal variance of R,
    // TT (a quarter of it), TRT and beyond (four times), and the logistic's scale.
    v_[0] = sqr(0.726f * bm + 0.812f * bm * bm + 3.7f * std::pow(bm, 20.f));
    v_[1] = 0.25f * v_[0];
    v_[2] = v_[3] = 4.f * v_[0];
    s_ = std::sqrt(kPi / 8.f) * (0.265f * bn + 1.194f * bn * bn + 5.372f * std::pow(bn, 22.f));
    // The scales shift R's cone by -2 alpha, TT's by alpha and TRT's by 4 alpha.
    const float alpha = p_.scale_tilt_deg * (kPi / 180.f), tilt[kLobes - 1] = {-2.f * alpha, alpha, 4.f * alpha};
    for (int p = 0; p < kLobes - 1; ++p) tilt_sin_[p] = std::sin(tilt[p]), tilt_cos_[p] = std::cos(tilt[p]);
}

HairBSDF::Incidence HairBSDF::incidence(const SurfaceInteraction &si, const Vec3 &wi) const {
    Incidence in;
    in.sin_theta = std::clamp(wi.y, -1.f, 1.f);
    in.cos_theta = safe_sqrt(1.f - sqr(in.sin_theta));
    in.phi = std::atan2(wi.z, wi.x);
    // From the normal (phi = pi/2) toward -s: phi_i = pi/2 + gamma_i.
    in.gamma = std::atan2(-wi.x, wi.z);
    const float h = std::sin(in.gamma), eta = p_.eta;

    // Refraction into the fibre: Bravais' index sqrt(eta^2 - sin^2 theta) / cos theta governs the
    // azimuth, Snell's law the longitudinal angle.
    const float bravais = safe_sqrt(sqr(eta) - sqr(in.sin_theta));
    const float sin_gamma_t = bravais > 0.f ? std::clamp(h * in.cos_theta / bravais, -1.f, 1.f) : 0.f;
    in.gamma_t = std::asin(sin_gamma_t);
    const float cos_gamma_t = safe_sqrt(1.f - sqr(sin_gamma_t));
    const float cos_theta_t = safe_sqrt(1.f - sqr(in.sin_theta / eta));
    // One crossing, in fibre radii: the chord 2 cos gamma_t, lengthened by the longitudinal slope.
    const float crossing = cos_theta_t > 0.f ? 2.f * cos_gamma_t / cos_theta_t : kInfinity;
    const Color sigma_a = vmax(p_.sigma_a->eval(si) * p_.sigma_a_scale, Color(0.f));
    const Color transmittance(std::exp(-sigma_a.x * crossing), std::exp(-sigma_a.y * crossing),
                              std::exp(-sigma_a.z * crossing));

    const float f = fresnel_dielectric(in.cos_theta * safe_sqrt(1.f - h * h), eta).r;
    Color *a = in.attenuation;
    a[0] = Color(f);
    a[1] = transmittance * sqr(1.f - f);
    a[2] = a[1] * transmittance * f;
    // Each longer walk reflects once more inside and crosses once more: a geometric series.
    for (int c = 0; c < 3; ++c) {
        const float tf = transmittance[c] * f;
        a[3][c] = tf < 1.f ? a[2][c] * tf / (1.f - tf) : 0.f;
    }
    float total = 0.f;
    for (int p = 0; p < kLobes; ++p) total += in.lobe_pdf[p] = luminance(a[p]);
    for (float &pdf : in.lobe_pdf) pdf = total > 0.f ? pdf / total : 0.f;
    return in;
}

std::pair<float, float> HairBSDF::tilted(const Incidence &in, int p) const {
    if (p == kLobes - 1) return {in.sin_theta, in.cos_theta};
    return {in.sin_theta * tilt_cos_[p] + in.cos_theta * tilt_sin_[p],
            std::abs(in.cos_theta * tilt_cos_[p] - in.sin_theta * tilt_sin_[p])};
}

float HairBSDF::azimuthal(const Incidence &in, int p, float dphi) const {
    return trimmed_logistic(std::remainder(dphi - specular_exit(in, p), 2.f * kPi), s_);
}

BSDFEval HairBSDF::scatter(const Incidence &in, const Vec3 &wo) const {
    const float sin_o = std::clamp(wo.y, -1.f, 1.f), cos_o = safe_sqrt(1.f - sqr(sin_o));
    const float dphi = std::atan2(wo.z, wo.x) - in.phi;
    BSDFEval r;
    for (int p = 0; p < kLobes; ++p) {
        const auto [sin_i, cos_i] = tilted(in, p);
        // The longer walks keep no azimuthal structure: uniform in phi.
        const float lobe = longitudinal(sin_i, cos_i, sin_o, cos_o, v_[p]) *
                           (p < kLobes - 1 ? azimuthal(in, p, dphi) : kInv2Pi);
        r.f += in.attenuation[p] * lobe;
        r.pdf += in.lobe_pdf[p] * lobe;
    }
    if (!is_finite(r.f) || !std::isfinite(r.pdf)) return {};
    return r;
}

Color HairBSDF::adjoint(const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    // eval carries |cos| of its second direction: f(wo, wi) |cos theta_o| = value(wo, wi) |wo.z| / |wi.z|.
    if (wi.z == 0.f) return Color(0.f);
    const Color f = scatter(incidence(si, wo), wi).f * (std::abs(wo.z) / std::abs(wi.z));
    return is_finite(f) ? f : Color(0.f);
}

BSDFEval HairBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
                            const Vec3 &wo) const {
    BSDFEval r = scatter(incidence(si, wi), wo);
    if (ctx.mode == TransportMode::Importance) r.f = adjoint(si, wi, wo);
    return r;
}

BSDFSample HairBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                            Vec2 u2) const {
    BSDFSample bs;
    const Incidence in = incidence(si, wi);
    if (!(in.lobe_pdf[0] + in.lobe_pdf[1] + in.lobe_pdf[2] + in.lobe_pdf[3] > 0.f)) return bs;
    // A lobe by its share of the attenuation's luminance; what is left of u1 then picks the azimuth.
    int p = 0;
    while (p < kLobes - 1 && u1 > in.lobe_pdf[p]) u1 -= in.lobe_pdf[p++];
    // (Rounding can leave u1 just past the last share; Mitsuba clamps it too.)
    const float u_phi = in.lobe_pdf[p] > 0.f ? std::min(u1 / in.lobe_pdf[p], 1.f) : 1.f;

    // The longitudinal lobe exactly (d'Eon et al. 2013): the cosine of the angle to the lobe's cone,
    // then a turn about it.
    const auto [sin_i, cos_i] = tilted(in, p);
    const float v = v_[p];
    const float cos_t = std::clamp(1.f + v * std::log(u2.x + (1.f - u2.x) * std::exp(-2.f / v)), -1.f, 1.f);
    const float sin_t = safe_sqrt(1.f - sqr(cos_t));
    const float sin_o = std::clamp(-cos_t * sin_i + sin_t * std::cos(2.f * kPi * u2.y) * cos_i, -1.f, 1.f);
    const float cos_o = safe_sqrt(1.f - sqr(sin_o));
    const float dphi = p < kLobes - 1 ? specular_exit(in, p) + sample_trimmed_logistic(u_phi, s_) : 2.f * kPi * u_phi;
    const float phi_o = in.phi + dphi;
    const Vec3 wo(cos_o * std::cos(phi_o), sin_o, cos_o * std::sin(phi_o));

    const BSDFEval e = scatter(in, wo);
    if (!(e.pdf > 0.f)) return bs;
    bs.wo = wo;
    bs.pdf = e.pdf;
    bs.eta = 1.f;  // the walk leaves the fibre where it entered
    bs.sampled_flags = wo.z * wi.z >= 0.f ? BSDFGlossyReflection : BSDFGlossyTransmission;
    bs.weight = (ctx.mode == TransportMode::Radiance ? e.f : adjoint(si, wi, wo)) / e.pdf;
    return bs;
}

}  // namespace neepp
