// Orthonormal frame: converts between world space and a local space whose z axis is the normal.
#pragma once
#include "neepp/math/vec.h"

namespace neepp {

struct Frame {
    Vec3 s, t, n;
    Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
    // Duff et al. 2017, "Building an orthonormal basis, revisited": branchless and continuous.
    explicit Frame(const Vec3 &normal) : n(normal) {
        float sign = std::copysign(1.f, n.z);
        float a = -1.f / (sign + n.z);
        float b = n.x * n.y * a;
        s = Vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
        t = Vec3(b, sign + n.y * n.y * a, -n.y);
    }
    Frame(const Vec3 &s_, const Vec3 &t_, const Vec3 &n_) : s(s_), t(t_), n(n_) {}
    Vec3 to_local(const Vec3 &v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
    Vec3 to_world(const Vec3 &v) const { return s * v.x + t * v.y + n * v.z; }
};

// Trigonometric helpers on local-frame directions (z = cos theta).
// The shading frame around n with s along dp/du made perpendicular to n (Gram-Schmidt), as Mitsuba aligns
// it, so anisotropic and bump-mapped materials have a consistent tangent; around n alone where dp/du has
// no part across n.
[[gnu::always_inline]] inline Frame frame_along(const Vec3 &n, const Vec3 &dpdu) {
    Vec3 s = dpdu - n * dot(n, dpdu);
    const float s2 = squared_norm(s);
    if (!(s2 > 1e-20f && std::isfinite(s2))) return Frame(n);
    s = s / std::sqrt(s2);
    return Frame(s, cross(n, s), n);
}

inline float cos_theta(const Vec3 &w) { return w.z; }
inline float abs_cos_theta(const Vec3 &w) { return std::abs(w.z); }
inline float cos2_theta(const Vec3 &w) { return w.z * w.z; }
inline float sin2_theta(const Vec3 &w) { return std::max(0.f, 1.f - w.z * w.z); }
inline float tan2_theta(const Vec3 &w) { return sin2_theta(w) / cos2_theta(w); }

}  // namespace neepp
