#include "neepp/shapes/analytic_uv.h"

#include <cmath>

namespace neepp {

namespace {
// Mitsuba's azimuth in [0, 2π).
float azimuth(float x, float y) {
    float phi = std::atan2(y, x);
    if (phi < 0.f) phi += 2.f * kPi;
    return phi;
}
}  // namespace

AnalyticUv::Partials AnalyticUv::at(const Vec3 &p) const {
    const Vec3 local = to_world.inverse().point(p);
    const float r = std::sqrt(local.x * local.x + local.y * local.y);
    // The direction of the point's azimuth; zero at the axis, where Mitsuba's partials vanish too.
    const float cos_phi = r > 0.f ? local.x / r : 0.f, sin_phi = r > 0.f ? local.y / r : 0.f;
    Partials q;
    if (surface == Surface::Disk) {
        q.uv = Vec2(r, azimuth(local.x, local.y) * kInv2Pi);
        q.dpdu = to_world.vector(Vec3(cos_phi, sin_phi, 0.f));
        q.dpdv = to_world.vector(Vec3(-sin_phi, cos_phi, 0.f)) * (2.f * kPi * r);
        q.n = normalize(to_world.normal(Vec3(0.f, 0.f, 1.f)));
    } else {
        // On the analytic cylinder the point lies at radius 1: a facet's inside is projected out to it.
        q.uv = Vec2(azimuth(local.x, local.y) * kInv2Pi, local.z);
        q.dpdu = to_world.vector(Vec3(-sin_phi, cos_phi, 0.f)) * (2.f * kPi);
        q.dpdv = to_world.vector(Vec3(0.f, 0.f, 1.f));
        q.n = normalize(to_world.normal(Vec3(cos_phi, sin_phi, 0.f)));
    }
    return q;
}

}  // namespace neepp
