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

BSDFEval RoughConductorBSDF::eval_pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi,
                                      const Vec3 &wo) const {
    if (wi.z <= 0.f || wo.z <= 0.f) return {};
    Vec3 h = normalize(wo + wi);
    MicrofacetDistribution distr = distribution(si);
    const float d = distr.eval(h);
    if (d == 0.f) return {};
    BSDFEval r;
    const float g1_i = distr.smith_g1(wi, h);
    // f cos_o = D G F / (4 cos_i cos_o) * cos_o
    r.f = fresnel(si, dot(wi, h)) * (d * (g1_i * distr.smith_g1(wo, h)) / (4.f * wi.z));
    // Same side tests that smith_g1 applies in sample(). Reflection Jacobian dm/dwo = 1 / (4 wo.m); with
    // visible normals wo.m = wi.m cancels.
    if (dot(wi, h) <= 0.f || dot(wo, h) <= 0.f) return r;
    r.pdf = sample_visible_ ? d * g1_i / (4.f * wi.z) : distr.pdf(wi, h) / (4.f * dot(wo, h));
    return r;
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
