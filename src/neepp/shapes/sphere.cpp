#include "neepp/shapes/sphere.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include "neepp/math/warp.h"

namespace neepp {

BBox Sphere::bounds() const {
    BBox b;
    b.expand(center - Vec3(radius));
    b.expand(center + Vec3(radius));
    return b;
}

RTCGeometry Sphere::embree_geometry(RTCDevice device) const {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    float *v = (float *)rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1);
    v[0] = center.x; v[1] = center.y; v[2] = center.z; v[3] = radius;
    return geom;
}

void Sphere::fill_interaction(uint32_t prim, float, float, const Ray &ray, float t, SurfaceInteraction &si) const {
    si.t = t;
    si.shape = this;
    si.prim_index = prim;
    si.p = ray.at(t);
    const Vec3 d = normalize(si.p - center);
    si.p = center + d * radius;  // re-project for precision
    si.n = flip_normals ? -d : d;
    const Vec3 local(dot(d, axes[0]), dot(d, axes[1]), dot(d, axes[2]));
    float phi = std::atan2(local.y, local.x);
    if (phi < 0) phi += 2.f * kPi;
    si.uv = Vec2(phi * kInv2Pi, std::acos(std::clamp(local.z, -1.f, 1.f)) * kInvPi);
    // Mitsuba's partials of p(u, v) = r (sin θ cos φ, sin θ sin φ, cos θ) with φ = 2π u, θ = π v: dp/dv points
    // toward the south pole, of length π r. Its length and sign set how far, and which way, a bump map's
    // slope along v tilts the normal.
    si.dpdu = (axes[1] * local.x - axes[0] * local.y) * (2.f * kPi * radius);
    const float rd = std::sqrt(local.x * local.x + local.y * local.y);
    if (rd > 0.f) {
        const float cos_phi = local.x / rd, sin_phi = local.y / rd;
        si.dpdv = (axes[0] * (local.z * cos_phi) + axes[1] * (local.z * sin_phi) - axes[2] * rd) * (kPi * radius);
    } else {
        si.dpdv = axes[0] * (kPi * radius);  // at a pole, as Mitsuba
    }
    // Aligned with dp/du where the BSDF reads tangents, as Mitsuba; at the poles dp/du vanishes.
    const float du2 = squared_norm(si.dpdu);
    if (tangents && du2 > 0.f) {
        const Vec3 s = si.dpdu / std::sqrt(du2);
        si.sh_frame = Frame(s, cross(si.n, s), si.n);
    } else {
        si.sh_frame = Frame(si.n);
    }
}

void Sphere::transform(const Transform &to_world) {
    const float scale = uniform_scale(to_world, "sphere to_world");
    center = to_world.point(center);
    radius *= scale;
    if (!(radius > 0) || !std::isfinite(radius) || !is_finite(center))
        throw std::runtime_error("sphere needs a positive radius and a finite center");
    for (Vec3 &axis : axes) axis = normalize(to_world.vector(axis));
}

PositionSample Sphere::sample_position(Vec2 u, bool) const {
    PositionSample ps;
    ps.pdf = pdf_position();
    Vec3 d = square_to_uniform_sphere(u);
    ps.p = center + d * radius;
    ps.n = ps.ns = flip_normals ? -d : d;
    return ps;
}

void Sphere::digest(GeometryDigest &d) const {
    d.add("sphere", 6);
    d.add(center);
    d.add(radius);
}

}  // namespace neepp
