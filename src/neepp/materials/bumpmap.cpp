#include "neepp/materials/bumpmap.h"

namespace neepp {

Frame BumpMapBSDF::perturbed_frame(const SurfaceInteraction &si, const Vec3 &wi) const {
    const Vec2 g = map().eval_1_grad(si) * scale_;
    const Vec3 &n = si.sh_frame.n;
    const Vec3 dpdu = si.dpdu + n * (g.x - dot(n, si.dpdu));
    const Vec3 dpdv = si.dpdv + n * (g.y - dot(n, si.dpdv));
    Vec3 pn = cross(dpdu, dpdv);
    if (dot(si.n, pn) < 0) pn = -pn;  // on the side of the geometric normal, whatever the uv orientation
    // The perturbed frame's s, as Mitsuba 3's bumpmap builds it: the unperturbed dp/du made orthogonal to the
    // perturbed normal, where Mitsuba takes dp/du's world coordinates as if they were coordinates in the hit's
    // shading frame (the normal there is local). Only a nested BSDF that is not isotropic sees s; with the
    // world dp/du instead, an anisotropic one shades unlike Mitsuba's wherever dp/du is not along world x.
    return oriented_frame(si, wi, si.to_local(pn), si.to_world(si.dpdu));
}

}  // namespace neepp
