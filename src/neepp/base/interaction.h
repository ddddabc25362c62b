// What a ray hit: position, normals, shading frame, texture coordinates and the shape's materials.
#pragma once
#include <cstdint>
#include "neepp/math/frame.h"
#include "neepp/math/vec.h"

namespace neepp {

class BSDF;
class Light;
class Shape;

// Mitsuba 3's offsets (math::RayEpsilon and ShadowEpsilon), larger than float precision alone needs:
// scenes made for Mitsuba are modelled around them. Bathroom's light bulbs are two glass shells 6e-5
// apart; with a smaller offset, a ray leaving one shell meets the other, which Mitsuba's rays step
// over, and the bulbs reflected in the mirror come out brighter than Mitsuba renders them.
inline constexpr float kRayEpsilon = 1500.f * 0x1p-24f;
inline constexpr float kShadowEpsilon = 10.f * kRayEpsilon;

// How far a ray origin is moved off a surface at p, along its normal, so it does not hit that surface
// again; the scale follows float precision at p.
inline float ray_epsilon(const Vec3 &p) {
    return kRayEpsilon * (1.f + std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))));
}

struct Ray {
    Vec3 o, d;
    float tmin = 0, tmax = kInfinity;
    Vec3 at(float t) const { return o + d * t; }
};

// A ray leaving the surface at p (geometric normal n) in direction d.
inline Ray spawn_ray(const Vec3 &p, const Vec3 &n, const Vec3 &d) {
    const float eps = ray_epsilon(p);
    return Ray{p + n * (dot(d, n) >= 0 ? eps : -eps), d, 0.f, kInfinity};
}

// A shadow ray from the surface at p (geometric normal n) toward point target, stopping just short of it
// so it does not hit the surface the target is on.
inline Ray spawn_ray_to(const Vec3 &p, const Vec3 &n, const Vec3 &target) {
    Ray r = spawn_ray(p, n, target - p);
    const Vec3 d = target - r.o;
    const float dist = norm(d);
    r.d = d / dist;
    r.tmax = dist * (1.f - kShadowEpsilon);
    return r;
}

struct SurfaceInteraction {
    Vec3 p;
    float t = kInfinity;
    Vec3 n;             // geometric normal (world space, unit, as the triangle winding gives it)
    Frame sh_frame;     // shading frame (interpolated vertex normal, unless face normals)
    Vec2 uv;
    Vec3 dpdu, dpdv;    // position derivatives w.r.t. uv (for bump mapping)
    Vec3 wi;            // direction toward the previous vertex, in the shading frame (Mitsuba's si.wi)
    const Shape *shape = nullptr;
    uint32_t prim_index = 0;

    bool is_valid() const { return shape != nullptr; }
    Vec3 to_local(const Vec3 &v) const { return sh_frame.to_local(v); }
    Vec3 to_world(const Vec3 &v) const { return sh_frame.to_world(v); }

    // A ray leaving the surface in direction d (world space).
    Ray spawn_ray(const Vec3 &d) const { return neepp::spawn_ray(p, n, d); }
    // A ray from this surface toward point target, stopping just short of it.
    Ray spawn_ray_to(const Vec3 &target) const { return neepp::spawn_ray_to(p, n, target); }
};

}  // namespace neepp
