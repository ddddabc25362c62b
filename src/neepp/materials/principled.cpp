#include "neepp/materials/principled.h"

#include <algorithm>
#include <cmath>

#include "neepp/materials/fresnel.h"
#include "neepp/math/warp.h"

namespace neepp {

namespace {

float lerp(float a, float b, float t) { return a * (1.f - t) + b * t; }

// Clearcoat's shadowing: Smith GGX at a fixed alpha of 0.25, as Burley.
const MicrofacetDistribution &clearcoat_shadowing() {
    static const MicrofacetDistribution d(MicrofacetType::GGX, 0.25f);
    return d;
}

float clearcoat_alpha(float gloss) { return lerp(0.1f, 0.001f, gloss); }

}  // namespace

namespace principled {

MicrofacetDistribution distribution(float roughness, float anisotropic) {
    const float r2 = sqr(roughness), aspect = std::sqrt(1.f - 0.9f * anisotropic);
    return MicrofacetDistribution(MicrofacetType::GGX, std::max(0.001f, r2 / aspect), std::max(0.001f, r2 * aspect));
}

Color tint_color(const Color &base_color) {
    float lum = luminance(base_color);
    return lum > 0.f ? base_color / lum : Color(1.f);
}

bool microfacet_compatible(const Vec3 &m, const Vec3 &wi, const Vec3 &wo, bool reflection) {
    const Vec3 m_wi = wi.z >= 0.f ? m : -m;
    const float wo_m = dot(wo, m_wi);
    return dot(wi, m_wi) > 0.f && (reflection ? wo_m > 0.f : wo_m < 0.f);
}

float diffuse_shape(float roughness, float abs_cos_i, float abs_cos_o, float cos_d, bool flatten, float flatness) {
    const float fo = schlick_weight(abs_cos_o), fi = schlick_weight(abs_cos_i);
    const float f_diffuse = (1.f - 0.5f * fi) * (1.f - 0.5f * fo);
    const float rr = 2.f * roughness * sqr(cos_d);
    const float shape = f_diffuse + rr * (fo + fi + fo * fi * (rr - 1.f));
    if (!flatten) return shape;
    const float fss90 = 0.5f * rr, fss = lerp(1.f, fss90, fo) * lerp(1.f, fss90, fi);
    const float f_ss = 1.25f * (fss * (1.f / (abs_cos_o + abs_cos_i) - 0.5f) + 0.5f);
    return lerp(shape, f_ss, flatness);
}

Color sheen_color(const Color &base_color, bool tinted, float sheen_tint) {
    if (!tinted) return Color(1.f);
    return Color(1.f - sheen_tint) + tint_color(base_color) * sheen_tint;
}

}  // namespace principled

using principled::microfacet_compatible;
using principled::schlick_r0;
using principled::tint_color;

float schlick_weight(float cos_theta) {
    const float m = std::clamp(1.f - cos_theta, 0.f, 1.f), m2 = m * m;
    return m2 * m2 * m;
}

Color schlick_fresnel(const Color &r0, float cos_theta_i, float eta) {
    const bool outside = cos_theta_i >= 0.f;
    const float eta_it = outside ? eta : 1.f / eta, eta_ti = outside ? 1.f / eta : eta;
    float w;
    if (eta_it > 1.f) {
        w = schlick_weight(std::abs(cos_theta_i));
    } else {
        const float cos_theta_t = safe_sqrt(1.f - (1.f - sqr(cos_theta_i)) * sqr(eta_ti));
        w = schlick_weight(cos_theta_t);
    }
    return r0 * (1.f - w) + Color(w);
}

float GTR1Distribution::eval(const Vec3 &m) const {
    const float cos_2 = sqr(m.z);
    const float d = (alpha_2_ - 1.f) / (kPi * std::log(alpha_2_) * (1.f + (alpha_2_ - 1.f) * cos_2));
    return d * m.z > 1e-20f ? d : 0.f;
}

Vec3 GTR1Distribution::sample(Vec2 u) const {
    const float phi = 2.f * kPi * u.x;
    const float cos_2 = (1.f - std::pow(alpha_2_, 1.f - u.y)) / (1.f - alpha_2_);
    const float sin_theta = safe_sqrt(1.f - cos_2), cos_theta = safe_sqrt(cos_2);
    return {std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta};
}

PrincipledBSDF::PrincipledBSDF(PrincipledParams p) : p_(std::move(p)) {
    if (!p_.base_color) p_.base_color = constant_texture(0.5f);
    if (!p_.roughness) p_.roughness = constant_texture(0.5f);
    flags_ = BSDFDiffuseReflection | BSDFGlossyReflection | (p_.spec_trans ? BSDFGlossyTransmission : 0u);
}

void PrincipledBSDF::prefetch(const SurfaceInteraction &si) const {
    prefetch_textures(si, p_.base_color, p_.roughness, p_.anisotropic, p_.metallic, p_.spec_trans, p_.spec_tint,
                      p_.sheen, p_.sheen_tint, p_.flatness, p_.clearcoat, p_.clearcoat_gloss);
}

PrincipledBSDF::Local PrincipledBSDF::lookup(const SurfaceInteraction &si) const {
    Local l;
    l.base_color = p_.base_color->eval(si);
    l.roughness = p_.roughness->eval_1(si);
    l.anisotropic = eval_or_zero(p_.anisotropic, si);
    l.metallic = eval_or_zero(p_.metallic, si);
    l.spec_trans = eval_or_zero(p_.spec_trans, si);
    l.spec_tint = eval_or_zero(p_.spec_tint, si);
    l.sheen = eval_or_zero(p_.sheen, si);
    l.sheen_tint = eval_or_zero(p_.sheen_tint, si);
    l.flatness = eval_or_zero(p_.flatness, si);
    l.clearcoat = eval_or_zero(p_.clearcoat, si);
    l.clearcoat_gloss = eval_or_zero(p_.clearcoat_gloss, si);
    return l;
}

MicrofacetDistribution PrincipledBSDF::specular_distribution(const Local &l) const {
    return principled::distribution(l.roughness, l.anisotropic);
}

PrincipledBSDF::LobeProbabilities PrincipledBSDF::lobe_probabilities(const Local &l, bool front_side,
                                                                     float fresnel) const {
    LobeProbabilities p;
    const float bsdf = l.bsdf();
    if (front_side) {
        p.reflection = p_.main_specular_sampling_rate * (1.f - bsdf * (1.f - fresnel));
        p.transmission = p_.spec_trans ? p_.main_specular_sampling_rate * bsdf * (1.f - fresnel) : 0.f;
        p.clearcoat = p_.clearcoat ? 0.25f * l.clearcoat * p_.clearcoat_sampling_rate : 0.f;
        p.diffuse = l.brdf() * p_.diffuse_reflectance_sampling_rate;
    } else {
        // From inside only the dielectric interface: Fresnel chooses.
        p.reflection = fresnel;
        p.transmission = p_.spec_trans ? 1.f - fresnel : 0.f;
    }
    const float total = p.reflection + p.transmission + p.clearcoat + p.diffuse;
    if (!(total > 0.f)) return {};
    const float inv = 1.f / total;
    p.reflection *= inv;
    p.transmission *= inv;
    p.clearcoat *= inv;
    p.diffuse *= inv;
    return p;
}

BSDFEval PrincipledBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
                                  const Vec3 &wo) const {
    const float cos_i = wi.z, cos_o = wo.z;
    const bool reflect = cos_i * cos_o > 0.f, refract = cos_i * cos_o < 0.f;
    if (!reflect && !refract) return {};  // grazing
    const bool front = cos_i > 0.f;
    const Local l = lookup(si);
    const float bsdf = l.bsdf(), brdf = l.brdf();
    // Seen from inside, or through the surface, only the transmissive part's dielectric interface exists.
    // (Mitsuba gives a density but no value there when that part is absent; a density of 0 agrees with
    // what its sampling does.)
    if ((!front || refract) && !(p_.spec_trans && bsdf > 0.f)) return {};

    const float eta_path = front ? p_.eta : 1.f / p_.eta;
    const Vec3 wh = dielectric_half_vector(wi, wo, reflect, eta_path);
    const float wi_h = dot(wi, wh), wo_h = dot(wo, wh);
    const float fresnel = fresnel_dielectric(wi_h, p_.eta).r;
    const LobeProbabilities prob = lobe_probabilities(l, front, fresnel);
    // |d wh / d wo|, the Jacobian of the half vector.
    const float dwh_dwo = dielectric_half_vector_jacobian(wi_h, wo_h, reflect, eta_path);

    BSDFEval r;
    if (microfacet_compatible(wh, wi, wo, reflect)) {
        const MicrofacetDistribution distr = specular_distribution(l);
        const float d = distr.eval(wh), g = distr.G(wi, wo, wh);
        const float specular_pdf = distr.pdf(front ? wi : -wi, wh) * dwh_dwo;
        if (reflect) {
            if (fresnel > 0.f) {
                Color f;
                if (front) {
                    // The dielectric's true Fresnel, with Schlick's for the metal and the tinted dielectric.
                    f = Color((1.f - l.metallic) * (1.f - l.spec_tint) * fresnel);
                    if (p_.metallic) f += l.metallic * schlick_fresnel(l.base_color, wi_h, p_.eta);
                    if (p_.spec_tint) {
                        const float eta_it = wi_h >= 0.f ? p_.eta : 1.f / p_.eta;
                        f += (1.f - l.metallic) * l.spec_tint *
                             schlick_fresnel(tint_color(l.base_color) * schlick_r0(eta_it), wi_h, p_.eta);
                    }
                } else {
                    f = Color(bsdf * fresnel);
                }
                r.f += f * (d * g / (4.f * std::abs(cos_i)));
            }
            r.pdf += prob.reflection * specular_pdf;
            if (p_.clearcoat) {
                const GTR1Distribution coat(clearcoat_alpha(l.clearcoat_gloss));
                if (front && l.clearcoat > 0.f) {
                    const float f = schlick_fresnel(Color(0.04f), wi_h, p_.eta).x;
                    r.f += Color(0.25f * l.clearcoat * f * coat.eval(wh) * clearcoat_shadowing().G(wi, wo, wh) *
                                 std::abs(cos_o));
                }
                r.pdf += prob.clearcoat * coat.pdf(wh) * dwh_dwo;
            }
        } else {
            if (fresnel < 1.f) {
                // The rough dielectric's transmission; radiance is compressed by eta^2 when it enters a denser
                // medium, importance is not.
                const float t = dielectric_microfacet_transmission(fresnel, d, g, wi_h, wo_h, cos_i, eta_path,
                                                                   ctx.mode == TransportMode::Radiance);
                const Color &c = l.base_color;
                r.f += Color(std::sqrt(c.x), std::sqrt(c.y), std::sqrt(c.z)) * (bsdf * t);
            }
            r.pdf += prob.transmission * specular_pdf;
        }
    }

    if (reflect && front) {
        r.pdf += prob.diffuse * square_to_cosine_hemisphere_pdf(wo);
        if (brdf > 0.f) {
            const float abs_cos_o = std::abs(cos_o), cos_d = dot(wh, wo);
            const float shape = principled::diffuse_shape(l.roughness, std::abs(cos_i), abs_cos_o, cos_d,
                                                          p_.flatness != nullptr, l.flatness);
            r.f += l.base_color * (brdf * abs_cos_o * kInvPi * shape);
            if (p_.sheen && l.sheen > 0.f && 1.f - l.metallic > 0.f)
                r.f += principled::sheen_color(l.base_color, p_.sheen_tint != nullptr, l.sheen_tint) *
                       (l.sheen * (1.f - l.metallic) * schlick_weight(std::abs(cos_d)) * abs_cos_o);
        }
    }
    return r;
}

BSDFSample PrincipledBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                                  Vec2 u2) const {
    if (wi.z == 0.f) return {};
    const bool front = wi.z > 0.f;
    const Local l = lookup(si);
    if (!front && !(p_.spec_trans && l.bsdf() > 0.f)) return {};

    // The specular normal is drawn first: its Fresnel reflectance splits the specular share.
    const Vec3 m = specular_distribution(l).sample_normal(front ? wi : -wi, u2);
    const FresnelResult fr = fresnel_dielectric(dot(wi, m), p_.eta);
    const LobeProbabilities prob = lobe_probabilities(l, front, fr.r);

    BSDFSample bs;
    Vec3 wo;
    bool ok;
    if (u1 < prob.diffuse) {
        wo = square_to_cosine_hemisphere(u2);
        bs.sampled_flags = BSDFDiffuseReflection;
        ok = wo.z > 0.f;
    } else if (u1 < prob.diffuse + prob.clearcoat) {
        const Vec3 mc = GTR1Distribution(clearcoat_alpha(l.clearcoat_gloss)).sample(u2);
        wo = reflect(wi, mc);
        bs.sampled_flags = BSDFGlossyReflection;
        ok = wi.z * wo.z > 0.f && microfacet_compatible(mc, wi, wo, true);
    } else if (u1 < prob.diffuse + prob.clearcoat + prob.transmission) {
        wo = refract(wi, m, fr.cos_theta_t, fr.eta_ti);
        bs.sampled_flags = BSDFGlossyTransmission;
        bs.eta = fr.eta_it;
        ok = wi.z * wo.z < 0.f && microfacet_compatible(m, wi, wo, false);
    } else {
        wo = reflect(wi, m);
        bs.sampled_flags = BSDFGlossyReflection;
        ok = wi.z * wo.z > 0.f && microfacet_compatible(m, wi, wo, true);
    }
    if (!ok) return {};
    // Every lobe can reach most directions: the weight is eval over the whole mixture's density.
    const BSDFEval e = eval_pdf(ctx, si, wi, wo);
    if (!(e.pdf > 0.f)) return {};
    bs.wo = wo;
    bs.pdf = e.pdf;
    bs.weight = e.f / e.pdf;
    return bs;
}

}  // namespace neepp
