#include "neepp/materials/dielectric.h"

#include "neepp/materials/fresnel.h"

namespace neepp {

DielectricBSDF::DielectricBSDF(float int_ior, float ext_ior, TexturePtr specular_reflectance,
                               TexturePtr specular_transmittance)
    : eta_(int_ior / ext_ior),
      specular_reflectance_(specular_reflectance ? std::move(specular_reflectance) : constant_texture(1.f)),
      specular_transmittance_(specular_transmittance ? std::move(specular_transmittance) : constant_texture(1.f)) {}

BSDFSample DielectricBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                                  Vec2) const {
    FresnelResult f = fresnel_dielectric(wi.z, eta_);
    BSDFSample bs;
    // Choosing the lobe with its Fresnel probability makes f/pdf equal to the texture multiplier alone.
    if (u1 <= f.r) {
        bs.wo = reflect_local(wi);
        bs.pdf = f.r;
        bs.sampled_flags = BSDFDeltaReflection;
        bs.weight = specular_reflectance_->eval(si);
    } else {
        bs.wo = refract_local(wi, f.cos_theta_t, f.eta_ti);
        bs.pdf = 1.f - f.r;
        bs.eta = f.eta_it;
        bs.sampled_flags = BSDFDeltaTransmission;
        float scale = ctx.mode == TransportMode::Radiance ? f.eta_ti * f.eta_ti : 1.f;
        bs.weight = specular_transmittance_->eval(si) * scale;
    }
    return bs;
}

}  // namespace neepp
