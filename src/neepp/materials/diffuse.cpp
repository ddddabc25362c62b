#include "neepp/materials/diffuse.h"

#include "neepp/math/warp.h"

namespace neepp {

BSDFEval DiffuseBSDF::eval_pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi,
                               const Vec3 &wo) const {
    const float pdf = density(wi, wo);
    if (!(pdf > 0)) return {};
    return {reflectance_->eval(si) * (kInvPi * cos_theta(wo)), pdf};
}

BSDFSample DiffuseBSDF::sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float,
                               Vec2 u2) const {
    BSDFSample bs;
    if (cos_theta(wi) <= 0) return bs;
    bs.wo = square_to_cosine_hemisphere(u2);
    bs.pdf = square_to_cosine_hemisphere_pdf(bs.wo);
    if (bs.pdf <= 0) return bs;
    bs.sampled_flags = BSDFDiffuseReflection;
    bs.weight = reflectance_->eval(si);  // f cos / pdf = (R/pi) cos / (cos/pi)
    return bs;
}

}  // namespace neepp
