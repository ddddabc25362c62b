#include "neepp/materials/principledthin.h"

#include <cmath>

#include "neepp/materials/fresnel.h"
#include "neepp/materials/principled.h"
#include "neepp/math/warp.h"

namespace neepp {

PrincipledThinBSDF::PrincipledThinBSDF(PrincipledThinParams p) : p_(std::move(p)) {
    if (!p_.base_color) p_.base_color = constant_texture(0.5f);
    if (!p_.roughness) p_.roughness = constant_texture(0.5f);
    if (!p_.eta) p_.eta = constant_texture(1.5f);
    flags_ = BSDFDiffuseReflection | BSDFGlossyReflection | (p_.spec_trans ? BSDFGlossyTransmission : 0u) |
             (p_.diff_trans ? BSDFDiffuseTransmission : 0u);
}

void PrincipledThinBSDF::prefetch(const SurfaceInteraction &si) const {
    prefetch_textures(si, p_.base_color, p_.roughness, p_.eta, p_.anisotropic, p_.spec_trans, p_.spec_tint, p_.sheen,
                      p_.sheen_tint, p_.flatness, p_.diff_trans);
}

PrincipledThinBSDF::Local PrincipledThinBSDF::lookup(const SurfaceInteraction &si) const {
    Local l;
    l.base_color = p_.base_color->eval(si);
    l.roughness = p_.roughness->eval_1(si);
    l.eta = p_.eta->eval_1(si);
    l.anisotropic = eval_or_zero(p_.anisotropic, si);
    l.spec_trans = eval_or_zero(p_.spec_trans, si);
    l.spec_tint = eval_or_zero(p_.spec_tint, si);
    l.sheen = eval_or_zero(p_.sheen, si);
    l.sheen_tint = eval_or_zero(p_.sheen_tint, si);
    l.flatness = eval_or_zero(p_.flatness, si);
    l.diff_trans = 0.5f * eval_or_zero(p_.diff_trans, si);  // given in [0, 2]
    return l;
}

PrincipledThinBSDF::LobeProbabilities PrincipledThinBSDF::lobe_probabilities(const Local &l) const {
    LobeProbabilities p;
    if (p_.spec_trans) {
        p.spec_reflection = 0.5f * l.spec_trans * p_.specular_reflectance_sampling_rate;
        p.spec_transmission = 0.5f * l.spec_trans * p_.specular_transmittance_sampling_rate;
    }
    p.diffuse_reflection = p_.diffuse_reflectance_sampling_rate * (1.f - l.spec_trans) * (1.f - l.diff_trans);
    if (p_.diff_trans)
        p.diffuse_transmission = p_.diffuse_transmittance_sampling_rate * (1.f - l.spec_trans) * l.diff_trans;
    const float total = p.spec_reflection + p.spec_transmission + p.diffuse_reflection + p.diffuse_transmission;
    if (!(total > 0.f)) return {};
    const float inv = 1.f / total;
    p.spec_reflection *= inv;
    p.spec_transmission *= inv;
    p.diffuse_reflection *= inv;
    p.diffuse_transmission *= inv;
    return p;
}

BSDFEval PrincipledThinBSDF::eval_pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi_in,
                                      const Vec3 &wo_in) const {
    if (wi_in.z == 0.f) return {};
    // A thin sheet is the same from both sides: seen from behind, mirror both directions.
    const float side = wi_in.z > 0.f ? 1.f : -1.f;
    const Vec3 wi = wi_in * side, wo = wo_in * side;
    const float cos_i = wi.z, cos_o = wo.z;
    const bool reflect = cos_o > 0.f, refract = cos_o < 0.f;
    if (!reflect && !refract) return {};
    const Local l = lookup(si);
    const LobeProbabilities prob = lobe_probabilities(l);

    // Transmission is a reflection mirrored through the sheet: both lobes share the half vector of wi and
    // wo brought back above.
    const Vec3 wo_up(wo.x, wo.y, std::abs(wo.z));
    const Vec3 wh = normalize(wi + wo_up);
    BSDFEval r;
    if (p_.spec_trans) {
        const float fresnel = fresnel_dielectric(dot(wi, wh), l.eta).r;
        const float dwh_dwo = std::abs(1.f / (4.f * dot(wo_up, wh)));
        if (principled::microfacet_compatible(wh, wi, wo, reflect)) {
            const MicrofacetDistribution distr = principled::distribution(
                reflect ? l.roughness : transmission_roughness(l), l.anisotropic);
            if (l.spec_trans > 0.f) {
                const float dg = distr.eval(wh) * distr.G(wi, wo, wh) / (4.f * cos_i);
                if (reflect) {
                    // The dielectric Fresnel, lerped toward Schlick's of the tinted dielectric by spec_tint.
                    Color f(fresnel * (1.f - l.spec_tint));
                    if (p_.spec_tint) {
                        const Color r0 = principled::tint_color(l.base_color) * principled::schlick_r0(l.eta);
                        f += schlick_fresnel(r0, dot(wi, wh), l.eta) * l.spec_tint;
                    }
                    r.f += f * (l.spec_trans * dg);
                } else {
                    r.f += l.base_color * (l.spec_trans * (1.f - fresnel) * dg);
                }
            }
            r.pdf += (reflect ? prob.spec_reflection : prob.spec_transmission) * distr.pdf(wi, wh) * dwh_dwo;
        }
    }
    if (reflect) {
        r.pdf += prob.diffuse_reflection * square_to_cosine_hemisphere_pdf(wo);
        if (l.spec_trans < 1.f && l.diff_trans < 1.f) {
            const float weight = (1.f - l.spec_trans) * (1.f - l.diff_trans), cos_d = dot(wh, wo);
            const float shape =
                principled::diffuse_shape(l.roughness, cos_i, cos_o, cos_d, p_.flatness != nullptr, l.flatness);
            r.f += l.base_color * (weight * cos_o * kInvPi * shape);
            if (p_.sheen)
                r.f += principled::sheen_color(l.base_color, p_.sheen_tint != nullptr, l.sheen_tint) *
                       (l.sheen * weight * schlick_weight(std::abs(cos_d)) * cos_o);
        }
    } else if (p_.diff_trans) {
        r.pdf += prob.diffuse_transmission * square_to_cosine_hemisphere_pdf(-wo);
        if (l.spec_trans < 1.f && l.diff_trans > 0.f)
            r.f += l.base_color * ((1.f - l.spec_trans) * l.diff_trans * kInvPi * -cos_o);
    }
    return r;
}

BSDFSample PrincipledThinBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi_in,
                                      float u1, Vec2 u2) const {
    if (wi_in.z == 0.f) return {};
    const float side = wi_in.z > 0.f ? 1.f : -1.f;
    const Vec3 wi = wi_in * side;
    const Local l = lookup(si);
    const LobeProbabilities prob = lobe_probabilities(l);

    BSDFSample bs;
    Vec3 wo;
    bool ok = true;
    if (u1 < prob.spec_reflection) {
        const Vec3 m = principled::distribution(l.roughness, l.anisotropic).sample_normal(wi, u2);
        wo = reflect(wi, m);
        bs.sampled_flags = BSDFGlossyReflection;
        ok = wo.z > 0.f && principled::microfacet_compatible(m, wi, wo, true);
    } else if (u1 < prob.spec_reflection + prob.spec_transmission) {
        const Vec3 m = principled::distribution(transmission_roughness(l), l.anisotropic).sample_normal(wi, u2);
        wo = reflect(wi, m);
        wo.z = -wo.z;  // straight through the sheet: no bending
        bs.sampled_flags = BSDFGlossyTransmission;
        ok = wo.z < 0.f && principled::microfacet_compatible(m, wi, wo, false);
    } else if (u1 < prob.spec_reflection + prob.spec_transmission + prob.diffuse_reflection) {
        wo = square_to_cosine_hemisphere(u2);
        bs.sampled_flags = BSDFDiffuseReflection;
    } else if (p_.diff_trans) {
        wo = -square_to_cosine_hemisphere(u2);
        bs.sampled_flags = BSDFDiffuseTransmission;
    } else {
        return {};
    }
    if (!ok) return {};
    wo = wo * side;
    const BSDFEval e = eval_pdf(ctx, si, wi_in, wo);
    if (!(e.pdf > 0.f)) return {};
    bs.wo = wo;
    bs.pdf = e.pdf;
    bs.weight = e.f / e.pdf;
    return bs;
}

}  // namespace neepp
