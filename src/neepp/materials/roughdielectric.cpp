#include "neepp/materials/roughdielectric.h"

#include <cmath>
#include <stdexcept>

#include "neepp/materials/fresnel.h"

namespace neepp {

RoughDielectricBSDF::RoughDielectricBSDF(MicrofacetType type, TexturePtr alpha_u, TexturePtr alpha_v, float int_ior,
                                         float ext_ior, TexturePtr specular_reflectance,
                                         TexturePtr specular_transmittance, bool sample_visible)
    : type_(type), alpha_u_(std::move(alpha_u)), alpha_v_(std::move(alpha_v)), eta_(int_ior / ext_ior),
      inv_eta_(1.f / eta_), specular_reflectance_(std::move(specular_reflectance)),
      specular_transmittance_(std::move(specular_transmittance)), sample_visible_(sample_visible) {
    if (!(int_ior > 0.f && ext_ior > 0.f) || int_ior == ext_ior)
        throw std::invalid_argument("the interior and exterior indices of refraction must be positive and differ");
}

MicrofacetDistribution RoughDielectricBSDF::distribution(const SurfaceInteraction &si) const {
    return MicrofacetDistribution(type_, alpha_u_->eval_1(si), alpha_v_->eval_1(si), sample_visible_);
}

MicrofacetDistribution RoughDielectricBSDF::sampling_distribution(const MicrofacetDistribution &distr,
                                                                  float cos_theta_i) const {
    if (sample_visible_) return distr;
    // Walter's widening: fewer normals that the incident direction barely sees, hence smaller weights.
    const float s = 1.2f - 0.2f * std::sqrt(std::abs(cos_theta_i));
    return MicrofacetDistribution(type_, distr.alpha_u() * s, distr.alpha_v() * s, false);
}

BSDFEval RoughDielectricBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
                                       const Vec3 &wo) const {
    const float cos_i = wi.z, cos_o = wo.z;
    if (cos_i == 0.f) return {};
    const bool reflect = cos_i * cos_o > 0.f;
    const float eta_path = cos_i > 0.f ? eta_ : inv_eta_;
    const Vec3 m = dielectric_half_vector(wi, wo, reflect, eta_path);
    const float wi_m = dot(wi, m), wo_m = dot(wo, m);
    // The microfacet must face wi and wo from the sides they are on (as smith_g1 tests in sample()).
    if (!(wi_m * cos_i > 0.f && wo_m * cos_o > 0.f)) return {};

    const MicrofacetDistribution distr = distribution(si);
    const float d = distr.eval(m), g = distr.G(wi, wo, m);
    const float fresnel = fresnel_dielectric(wi_m, eta_).r;
    BSDFEval r;
    if (reflect) {
        r.f = Color(fresnel * d * g / (4.f * std::abs(cos_i)));
        if (specular_reflectance_) r.f = r.f * specular_reflectance_->eval(si);
    } else {
        r.f = Color(dielectric_microfacet_transmission(fresnel, d, g, wi_m, wo_m, cos_i, eta_path,
                                                       ctx.mode == TransportMode::Radiance));
        if (specular_transmittance_) r.f = r.f * specular_transmittance_->eval(si);
    }
    const Vec3 wi_up = cos_i > 0.f ? wi : -wi;
    r.pdf = sampling_distribution(distr, cos_i).pdf(wi_up, m) * (reflect ? fresnel : 1.f - fresnel) *
            dielectric_half_vector_jacobian(wi_m, wo_m, reflect, eta_path);
    return r;
}

BSDFSample RoughDielectricBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
                                       float u1, Vec2 u2) const {
    const float cos_i = wi.z;
    if (cos_i == 0.f) return {};
    const MicrofacetDistribution distr = distribution(si);
    auto [m, m_pdf] = sampling_distribution(distr, cos_i).sample(cos_i > 0.f ? wi : -wi, u2);
    if (m_pdf == 0.f) return {};
    const FresnelResult fr = fresnel_dielectric(dot(wi, m), eta_);

    BSDFSample bs;
    Color weight(1.f);
    float dwh_dwo;
    // The Fresnel reflectance chooses: f / pdf then keeps only the shadowing and the multiplier.
    if (u1 <= fr.r) {
        bs.wo = reflect(wi, m);
        bs.pdf = m_pdf * fr.r;
        bs.sampled_flags = BSDFGlossyReflection;
        if (specular_reflectance_) weight = specular_reflectance_->eval(si);
        dwh_dwo = 1.f / (4.f * dot(bs.wo, m));
    } else {
        bs.wo = refract(wi, m, fr.cos_theta_t, fr.eta_ti);
        bs.pdf = m_pdf * (1.f - fr.r);
        bs.eta = fr.eta_it;
        bs.sampled_flags = BSDFGlossyTransmission;
        if (ctx.mode == TransportMode::Radiance) weight = Color(sqr(fr.eta_ti));
        if (specular_transmittance_) weight = weight * specular_transmittance_->eval(si);
        const float wo_m = dot(bs.wo, m);
        dwh_dwo = sqr(bs.eta) * wo_m / sqr(dot(wi, m) + bs.eta * wo_m);
    }
    // Zero, through G1, when wo ends up on the side its lobe cannot reach.
    weight = weight * (sample_visible_ ? distr.smith_g1(bs.wo, m)
                                       : distr.G(wi, bs.wo, m) * dot(wi, m) / (cos_i * m.z));
    bs.pdf *= std::abs(dwh_dwo);
    bs.weight = weight;
    return bs;
}

}  // namespace neepp
