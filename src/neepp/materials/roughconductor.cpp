#include "neepp/materials/roughconductor.h"

#include "neepp/materials/fresnel.h"

namespace neepp {

RoughConductorBSDF::RoughConductorBSDF(MicrofacetType type, TexturePtr alpha_u, TexturePtr alpha_v, TexturePtr eta,
                                       TexturePtr k, TexturePtr specular_reflectance, bool sample_visible)
    : type_(type), alpha_u_(std::move(alpha_u)), alpha_v_(std::move(alpha_v)), eta_(std::move(eta)),
      k_(std::move(k)),
      specular_reflectance_(specular_reflectance ? std::move(specular_reflectance) : constant_texture(1.f)),
      sample_visible_(sample_visible) {}

MicrofacetDistribution RoughConductorBSDF::distribution(const SurfaceInteraction &si) const {
    return MicrofacetDistribution(type_, alpha_u_->eval_1(si), alpha_v_->eval_1(si), sample_visible_);
}

Color RoughConductorBSDF::fresnel(const SurfaceInteraction &si, float cos_theta) const {
    return fresnel_conductor(cos_theta, eta_->eval(si), k_->eval(si)) * specular_reflectance_->eval(si);
}

Color RoughConductorBSDF::eval(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi,
                               const Vec3 &wo) const {
    if (wi.z <= 0.f || wo.z <= 0.f) return Color(0.f);
    Vec3 h = normalize(wo + wi);
    MicrofacetDistribution distr = distribution(si);
    float d = distr.eval(h);
    if (d == 0.f) return Color(0.f);
    // f cos_o = D G F / (4 cos_i cos_o) * cos_o
    return fresnel(si, dot(wi, h)) * (d * distr.G(wi, wo, h) / (4.f * wi.z));
}

float RoughConductorBSDF::pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi,
                              const Vec3 &wo) const {
    Vec3 m = normalize(wo + wi);
    // Same side tests that smith_g1 applies in eval() and sample().
    if (wi.z <= 0.f || wo.z <= 0.f || dot(wi, m) <= 0.f || dot(wo, m) <= 0.f) return 0.f;
    MicrofacetDistribution distr = distribution(si);
    // Reflection Jacobian dm/dwo = 1 / (4 wo.m); with visible normals wo.m = wi.m cancels.
    if (sample_visible_) return distr.eval(m) * distr.smith_g1(wi, m) / (4.f * wi.z);
    return distr.pdf(wi, m) / (4.f * dot(wo, m));
}

BSDFSample RoughConductorBSDF::sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float,
                                      Vec2 u2) const {
    BSDFSample bs;
    if (wi.z <= 0.f) return bs;
    MicrofacetDistribution distr = distribution(si);
    auto [m, m_pdf] = distr.sample(wi, u2);
    Vec3 wo = reflect(wi, m);
    if (m_pdf == 0.f || wo.z <= 0.f) return bs;

    // weight = f cos_o / pdf; with visible normals most factors cancel, leaving G1(wo) F.
    float weight = sample_visible_ ? distr.smith_g1(wo, m) : distr.G(wi, wo, m) * dot(wi, m) / (wi.z * m.z);
    bs.wo = wo;
    bs.pdf = m_pdf / (4.f * dot(wo, m));
    bs.sampled_flags = BSDFGlossyReflection;
    bs.weight = fresnel(si, dot(wi, m)) * weight;
    return bs;
}

}  // namespace neepp
