#include "neepp/materials/plastic.h"

#include "neepp/materials/fresnel.h"
#include "neepp/math/warp.h"

namespace neepp {

namespace {
float channel_mean(const Color &c) { return (c.x + c.y + c.z) * (1.f / 3.f); }
}  // namespace

float specular_sampling_weight(const Texture &diffuse, const Texture &specular) {
    float d_mean = channel_mean(diffuse.mean()), s_mean = channel_mean(specular.mean());
    return s_mean / (d_mean + s_mean);
}

PlasticBSDF::PlasticBSDF(float int_ior, float ext_ior, TexturePtr diffuse_reflectance,
                         TexturePtr specular_reflectance, bool nonlinear)
    : eta_(int_ior / ext_ior), inv_eta_2_(1.f / (eta_ * eta_)), fdr_int_(fresnel_diffuse_reflectance(1.f / eta_)),
      diffuse_reflectance_(std::move(diffuse_reflectance)),
      specular_reflectance_(specular_reflectance ? std::move(specular_reflectance) : constant_texture(1.f)),
      nonlinear_(nonlinear),
      specular_sampling_weight_(specular_sampling_weight(*diffuse_reflectance_, *specular_reflectance_)) {}

float PlasticBSDF::prob_specular(float f_i) const {
    float p_s = f_i * specular_sampling_weight_, p_d = (1.f - f_i) * (1.f - specular_sampling_weight_);
    return p_s / (p_s + p_d);
}

// Diffuse lobe divided by the cosine-hemisphere density: light refracts in (1 - f_i), bounces between the
// base and the coating (geometric series over internal reflectance fdr_int), refracts out (1 - f_o), and
// is compressed into the exterior solid angle (1 / eta^2).
Color PlasticBSDF::diffuse_term(const SurfaceInteraction &si, float f_i, float f_o) const {
    Color diff = diffuse_reflectance_->eval(si);
    Color denom = nonlinear_ ? Color(1.f) - diff * fdr_int_ : Color(1.f - fdr_int_);
    return diff / denom * (inv_eta_2_ * (1.f - f_i) * (1.f - f_o));
}

Color PlasticBSDF::eval(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    if (wi.z <= 0.f || wo.z <= 0.f) return Color(0.f);
    float f_i = fresnel_dielectric(wi.z, eta_).r, f_o = fresnel_dielectric(wo.z, eta_).r;
    return diffuse_term(si, f_i, f_o) * square_to_cosine_hemisphere_pdf(wo);
}

float PlasticBSDF::pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &wi, const Vec3 &wo) const {
    if (wi.z <= 0.f || wo.z <= 0.f) return 0.f;
    float f_i = fresnel_dielectric(wi.z, eta_).r;
    return square_to_cosine_hemisphere_pdf(wo) * (1.f - prob_specular(f_i));
}

BSDFSample PlasticBSDF::sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                               Vec2 u2) const {
    BSDFSample bs;
    if (wi.z <= 0.f) return bs;
    float f_i = fresnel_dielectric(wi.z, eta_).r, p_spec = prob_specular(f_i);
    if (u1 < p_spec) {
        bs.wo = reflect_local(wi);
        bs.pdf = p_spec;
        bs.sampled_flags = BSDFDeltaReflection;
        bs.weight = specular_reflectance_->eval(si) * (f_i / p_spec);
        return bs;
    }
    float p_diff = 1.f - p_spec;
    bs.wo = square_to_cosine_hemisphere(u2);
    bs.pdf = p_diff * square_to_cosine_hemisphere_pdf(bs.wo);
    if (bs.pdf <= 0.f) return BSDFSample{};
    bs.sampled_flags = BSDFDiffuseReflection;
    float f_o = fresnel_dielectric(bs.wo.z, eta_).r;
    bs.weight = diffuse_term(si, f_i, f_o) / p_diff;
    return bs;
}

}  // namespace neepp
