#include "neepp/materials/conductor.h"

#include "neepp/materials/fresnel.h"

namespace neepp {

ConductorBSDF::ConductorBSDF(TexturePtr eta, TexturePtr k, TexturePtr specular_reflectance)
    : eta_(std::move(eta)), k_(std::move(k)),
      specular_reflectance_(specular_reflectance ? std::move(specular_reflectance) : constant_texture(1.f)) {}

BSDFSample ConductorBSDF::sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float,
                                 Vec2) const {
    BSDFSample bs;
    float cos_theta_i = wi.z;
    if (cos_theta_i <= 0.f) return bs;  // one-sided: black from below
    bs.wo = reflect_local(wi);
    bs.pdf = 1.f;
    bs.sampled_flags = BSDFDeltaReflection;
    bs.weight = specular_reflectance_->eval(si) * fresnel_conductor(cos_theta_i, eta_->eval(si), k_->eval(si));
    return bs;
}

}  // namespace neepp
