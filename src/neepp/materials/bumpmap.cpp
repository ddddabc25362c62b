#include "neepp/materials/bumpmap.h"

namespace neepp {

Frame BumpMapBSDF::perturbed_frame(const SurfaceInteraction &si, const Vec3 &wi) const {
    const Vec2 g = map().eval_1_grad(si) * scale_;
    const Vec3 &n = si.sh_frame.n;
    const Vec3 dpdu = si.dpdu + n * (g.x - dot(n, si.dpdu));
    const Vec3 dpdv = si.dpdv + n * (g.y - dot(n, si.dpdv));
    Vec3 pn = cross(dpdu, dpdv);
    if (dot(si.n, pn) < 0) pn = -pn;  // on the side of the geometric normal, whatever the uv orientation
    return oriented_frame(si, wi, si.to_local(pn), dpdu);
}

}  // namespace neepp
