// Warps from the unit square to common domains, with their densities.
#pragma once
#include "neepp/math/trig.h"
#include "neepp/math/vec.h"

namespace neepp {

inline Vec2 square_to_uniform_disk_concentric(Vec2 u) {
    float a = 2.f * u.x - 1.f, b = 2.f * u.y - 1.f;
    if (a == 0 && b == 0) return {0, 0};
    // The angle is pi/4 * (b/a), or pi/2 - pi/4 * (a/b), whose cosine and sine are the sine and cosine
    // of pi/4 * (a/b): either way a polynomial on [-pi/4, pi/4] gives them.
    if (std::abs(a) > std::abs(b)) {
        const SinCos t = sincos_quarter((kPi / 4.f) * (b / a));
        return {a * t.cos, a * t.sin};
    }
    const SinCos t = sincos_quarter((kPi / 4.f) * (a / b));
    return {b * t.sin, b * t.cos};
}

inline Vec3 square_to_cosine_hemisphere(Vec2 u) {
    Vec2 d = square_to_uniform_disk_concentric(u);
    float z = safe_sqrt(1.f - d.x * d.x - d.y * d.y);
    return {d.x, d.y, z};
}
inline float square_to_cosine_hemisphere_pdf(const Vec3 &v) { return v.z > 0 ? v.z * kInvPi : 0.f; }

inline Vec3 square_to_uniform_sphere(Vec2 u) {
    const float z = 1.f - 2.f * u.y, r = safe_sqrt(1.f - z * z);
    const SinCos phi = sincos_turns(u.x);
    return {r * phi.cos, r * phi.sin, z};
}
inline float square_to_uniform_sphere_pdf() { return kInv4Pi; }

inline Vec3 square_to_uniform_hemisphere(Vec2 u) {
    const float z = u.y, r = safe_sqrt(1.f - z * z);
    const SinCos phi = sincos_turns(u.x);
    return {r * phi.cos, r * phi.sin, z};
}
inline float square_to_uniform_hemisphere_pdf() { return kInv2Pi; }

// Uniform direction within a cone of half-angle acos(cos_max) around +z.
inline Vec3 square_to_uniform_cone(Vec2 u, float cos_max) {
    const float cos_t = (1.f - u.y) + u.y * cos_max, sin_t = safe_sqrt(1.f - cos_t * cos_t);
    const SinCos phi = sincos_turns(u.x);
    return {sin_t * phi.cos, sin_t * phi.sin, cos_t};
}
inline float square_to_uniform_cone_pdf(float cos_max) { return 1.f / (2.f * kPi * (1.f - cos_max)); }

// Barycentric coordinates (b1, b2) of a uniformly distributed point on a triangle.
inline Vec2 square_to_uniform_triangle(Vec2 u) {
    float t = safe_sqrt(1.f - u.x);
    return {1.f - t, t * u.y};
}

// Power heuristic with beta = 2 (Veach), as in Mitsuba's path integrator.
inline float mis_power(float pdf_a, float pdf_b) {
    float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
    return a > 0 ? a / (a + b) : 0.f;
}

}  // namespace neepp
