// What a ray hit: position, normals, shading frame, texture coordinates and the shape's materials.
#pragma once
#include <cstdint>
#include "neepp/math/frame.h"
#include "neepp/math/vec.h"

namespace neepp {

class BSDF;
class Light;
struct Shape;

// Offset a ray origin off a surface to avoid self-intersection; the scale follows float precision at p.
inline float ray_epsilon(const Vec3 &p) {
    return 1e-5f * (1.f + std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))));
}

struct Ray {
    Vec3 o, d;
    float tmin = 0, tmax = kInfinity;
    Vec3 at(float t) const { return o + d * t; }
};

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
    // The last bitmap-texture lookup made at this point: a BSDF reads its textures when next event
    // estimation evaluates it and again when it is sampled, and the second read is then a copy; the
    // prefetch before both leaves the texel footprint it located, so the first read does not locate it
    // again. Keyed by the texture and the uv (a bitmap's value depends on nothing else), so it never needs
    // resetting and a SurfaceInteraction moved to another uv cannot return a stale value.
    struct TextureMemo {
        const void *texture = nullptr;
        Vec2 uv;
        bool has_value = false;  // else only located (by a prefetch): footprint and weights below
        Color value;
        int texel[4];            // bilinear footprint: x0, x1, y0, y1
        float weight[4];         // wx0, wx1, wy0, wy1
    };
    mutable TextureMemo texture_memo;

    bool is_valid() const { return shape != nullptr; }
    Vec3 to_local(const Vec3 &v) const { return sh_frame.to_local(v); }
    Vec3 to_world(const Vec3 &v) const { return sh_frame.to_world(v); }

    // A ray leaving the surface in direction d (world space).
    Ray spawn_ray(const Vec3 &d) const {
        float eps = ray_epsilon(p);
        Vec3 o = p + n * (dot(d, n) >= 0 ? eps : -eps);
        return Ray{o, d, 0.f, kInfinity};
    }
    // A ray from this surface toward point target, stopping just short of it.
    Ray spawn_ray_to(const Vec3 &target) const {
        Vec3 d = target - p;
        float eps = ray_epsilon(p);
        Vec3 o = p + n * (dot(d, n) >= 0 ? eps : -eps);
        d = target - o;
        float dist = norm(d);
        return Ray{o, d / dist, 0.f, dist * (1.f - 1e-4f)};
    }
};

}  // namespace neepp
