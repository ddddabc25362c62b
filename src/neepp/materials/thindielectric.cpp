#include "neepp/materials/thindielectric.h"

#include "neepp/materials/fresnel.h"

namespace neepp {

ThinDielectricBSDF::ThinDielectricBSDF(float int_ior, float ext_ior, TexturePtr specular_reflectance,
                                       TexturePtr specular_transmittance)
    : eta_(int_ior / ext_ior),
      specular_reflectance_(specular_reflectance ? std::move(specular_reflectance) : constant_texture(1.f)),
      specular_transmittance_(specular_transmittance ? std::move(specular_transmittance) : constant_texture(1.f)) {}

float ThinDielectricBSDF::reflectance(const Vec3 &wi) const {
    float r = fresnel_dielectric(std::abs(wi.z), eta_).r;
    return r * 2.f / (1.f + r);  // r + t r t + t r^3 t + ... with t = 1 - r
}

Color ThinDielectricBSDF::null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const {
    return specular_transmittance_->eval(si) * (1.f - reflectance(wi));
}

BSDFSample ThinDielectricBSDF::sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                                      Vec2) const {
    float r = reflectance(wi);
    BSDFSample bs;
    if (u1 <= r) {
        bs.wo = reflect_local(wi);
        bs.pdf = r;
        bs.sampled_flags = BSDFDeltaReflection;
        bs.weight = specular_reflectance_->eval(si);
    } else {
        bs.wo = -wi;
        bs.pdf = 1.f - r;
        bs.sampled_flags = BSDFNull;
        bs.weight = specular_transmittance_->eval(si);
    }
    return bs;
}

}  // namespace neepp
