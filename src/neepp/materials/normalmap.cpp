#include "neepp/materials/normalmap.h"

namespace neepp {

Frame NormalMapBSDF::perturbed_frame(const SurfaceInteraction &si, const Vec3 &wi) const {
    const Color c = map().eval(si);
    // The tangent-space x axis stays the tangent (Mitsuba's frame: s is x made orthogonal to n).
    return oriented_frame(si, wi, Vec3(2.f * c.x - 1.f, 2.f * c.y - 1.f, 2.f * c.z - 1.f), si.sh_frame.s);
}

}  // namespace neepp
