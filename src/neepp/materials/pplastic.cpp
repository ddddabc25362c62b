#include "neepp/materials/pplastic.h"

#include "neepp/materials/fresnel.h"
#include "neepp/materials/plastic.h"
#include "neepp/math/warp.h"

namespace neepp {

PolarizedPlasticBSDF::PolarizedPlasticBSDF(MicrofacetType type, TexturePtr alpha_u, TexturePtr alpha_v, float eta,
                                           TexturePtr diffuse_reflectance, TexturePtr specular_reflectance,
                                           bool sample_visible)
    : type_(type), alpha_u_(std::move(alpha_u)), alpha_v_(std::move(alpha_v)), eta_(eta),
      diffuse_reflectance_(std::move(diffuse_reflectance)),
      specular_reflectance_(specular_reflectance ? std::move(specular_reflectance) : constant_texture(1.f)),
      sample_visible_(sample_visible),
      specular_sampling_weight_(specular_sampling_weight(*diffuse_reflectance_, *specular_reflectance_)) {}

MicrofacetDistribution PolarizedPlasticBSDF::distribution(const SurfaceInteraction &si) const {
    return MicrofacetDistribution(type_, alpha_u_->eval_1(si), alpha_v_->eval_1(si), sample_visible_);
}

BSDFEval PolarizedPlasticBSDF::eval_pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi,
                                        const Vec3 &wo) const {
    if (wi.z <= 0.f || wo.z <= 0.f) return {};
    const MicrofacetDistribution distr = distribution(si);
    const Vec3 h = normalize(wo + wi);
    const float d = distr.eval(h), g1_i = distr.smith_g1(wi, h);
    const float f = fresnel_dielectric(dot(wi, h), eta_).r;
    BSDFEval r;
    r.f = specular_reflectance_->eval(si) * (f * d * g1_i * distr.smith_g1(wo, h) / (4.f * wi.z));
    const float t_i = 1.f - fresnel_dielectric(wi.z, eta_).r, t_o = 1.f - fresnel_dielectric(wo.z, eta_).r;
    r.f += diffuse_reflectance_->eval(si) * (t_i * t_o * kInvPi * wo.z);

    const float spec = dot(wi, h) > 0.f && dot(wo, h) > 0.f ? distr.reflection_pdf(wi, wo, h, d, g1_i) : 0.f;
    r.pdf = specular_sampling_weight_ * spec + (1.f - specular_sampling_weight_) * square_to_cosine_hemisphere_pdf(wo);
    return r;
}

BSDFSample PolarizedPlasticBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
                                        float u1, Vec2 u2) const {
    BSDFSample bs;
    if (wi.z <= 0.f) return bs;
    if (u1 < specular_sampling_weight_) {
        bs.wo = reflect(wi, distribution(si).sample_normal(wi, u2));
        bs.sampled_flags = BSDFGlossyReflection;
    } else {
        bs.wo = square_to_cosine_hemisphere(u2);
        bs.sampled_flags = BSDFDiffuseReflection;
    }
    // Either lobe can produce either direction: the weight uses the mixture's density.
    const BSDFEval e = eval_pdf(ctx, si, wi, bs.wo);
    if (!(e.pdf > 0.f)) return BSDFSample{};
    bs.pdf = e.pdf;
    bs.weight = e.f / e.pdf;
    return bs;
}

}  // namespace neepp
