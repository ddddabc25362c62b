#include "neepp/base/light_bounds.h"

#include <algorithm>
#include <cmath>

namespace neepp {

namespace {

float safe_acos(float c) { return std::acos(std::clamp(c, -1.f, 1.f)); }

// Rotates unit vector a toward unit vector b (not parallel) by angle t, in the plane they span.
Vec3 rotate_toward(const Vec3 &a, const Vec3 &b, float t) {
    Vec3 ortho = b - a * dot(a, b);
    float len = norm(ortho);
    if (!(len > 1e-7f)) return a;
    ortho = ortho / len;
    return normalize(a * std::cos(t) + ortho * std::sin(t));
}

// cos(max(0, alpha - beta)) from the cosines and sines of alpha and beta (both in [0, pi]).
void cos_sin_of_clamped_difference(float cos_a, float sin_a, float cos_b, float sin_b, float &cos_out, float &sin_out) {
    if (cos_a >= cos_b) {  // alpha <= beta
        cos_out = 1.f;
        sin_out = 0.f;
        return;
    }
    cos_out = cos_a * cos_b + sin_a * sin_b;
    sin_out = sin_a * cos_b - cos_a * sin_b;
}

}  // namespace

DirectionCone cone_union(const DirectionCone &a, const DirectionCone &b) {
    if (a.is_entire_sphere() || b.is_entire_sphere()) return DirectionCone::entire_sphere();
    const float theta_a = safe_acos(a.cos_theta), theta_b = safe_acos(b.cos_theta);
    const float theta_d = safe_acos(dot(a.w, b.w));
    if (std::min(theta_d + theta_b, kPi) <= theta_a) return a;  // b inside a
    if (std::min(theta_d + theta_a, kPi) <= theta_b) return b;  // a inside b
    const float theta_o = 0.5f * (theta_a + theta_d + theta_b);
    if (theta_o >= kPi) return DirectionCone::entire_sphere();
    const float theta_r = theta_o - theta_a;  // rotate a's axis toward b's by this much
    if (squared_norm(cross(a.w, b.w)) < 1e-12f) {
        // Parallel axes: no plane to rotate in. Same direction: a's axis, widened to cover b's cone
        // (conservatively); opposite directions: only the whole sphere holds both.
        if (dot(a.w, b.w) < 0) return DirectionCone::entire_sphere();
        return {a.w, std::cos(std::min(std::max(theta_a, theta_b) + theta_d, kPi))};
    }
    return {rotate_toward(a.w, b.w, theta_r), std::cos(theta_o)};
}

LightBounds bounds_union(const LightBounds &a, const LightBounds &b) {
    if (a.phi <= 0) return b;
    if (b.phi <= 0) return a;
    LightBounds u;
    u.bounds = a.bounds;
    u.bounds.expand(b.bounds);
    u.normals = cone_union(a.normals, b.normals);
    u.cos_theta_e = std::min(a.cos_theta_e, b.cos_theta_e);
    u.phi = a.phi + b.phi;
    u.two_sided = a.two_sided || b.two_sided;
    return u;
}

float LightBounds::importance(const Vec3 &p, const Vec3 &n) const { return CompactLightBounds(*this).importance(p, n); }

CompactLightBounds::CompactLightBounds(const LightBounds &b)
    : center(b.bounds.center()), w(b.normals.w), r2(0.25f * squared_norm(b.bounds.extent())),
      cos_o(b.normals.cos_theta), sin_o(std::sqrt(std::max(0.f, 1.f - b.normals.cos_theta * b.normals.cos_theta))),
      cos_e(b.cos_theta_e), phi(b.phi), two_sided(b.two_sided) {}

float CompactLightBounds::importance(const Vec3 &p, const Vec3 &n) const {
    if (!(phi > 0)) return 0.f;
    const float dist2 = squared_norm(p - center);
    // Inside (or very near) the bounds the 1/d² falloff means nothing: clamp d² to the bounds' size
    // (r2: the squared radius of the bounding sphere).
    const float d2 = std::max(dist2, r2);
    const Vec3 wi = dist2 > 0 ? (p - center) / std::sqrt(dist2) : Vec3(0, 0, 1);  // from the lights to p

    // Angle subtended by the bounding sphere (theta_b); the whole sphere when p is inside it.
    float cos_b = -1.f, sin_b = 0.f;
    if (dist2 > r2) {
        const float sin2 = r2 / dist2;
        sin_b = std::sqrt(sin2);
        cos_b = std::sqrt(std::max(0.f, 1.f - sin2));
    }
    // Emission side: theta' = max(0, theta_w - theta_o - theta_b).
    float cos_w = dot(w, wi);
    if (two_sided) cos_w = std::abs(cos_w);
    const float sin_w = std::sqrt(std::max(0.f, 1.f - cos_w * cos_w));
    float cos_wo, sin_wo, cos_p, sin_p;
    cos_sin_of_clamped_difference(cos_w, sin_w, cos_o, sin_o, cos_wo, sin_wo);
    if (dist2 > r2) cos_sin_of_clamped_difference(cos_wo, sin_wo, cos_b, sin_b, cos_p, sin_p);
    else cos_p = 1.f;
    if (cos_p <= cos_e) return 0.f;
    float importance = phi * cos_p / d2;

    // Receiver side: the smallest angle between n and a direction toward the bounds. |cos| because the
    // receiver may transmit; a one-sided receiver only makes the bound looser.
    if (dist2 > r2 && (n.x != 0 || n.y != 0 || n.z != 0)) {
        const float cos_i = std::abs(dot(n, wi));
        const float sin_i = std::sqrt(std::max(0.f, 1.f - cos_i * cos_i));
        float cos_ip, sin_ip;
        cos_sin_of_clamped_difference(cos_i, sin_i, cos_b, sin_b, cos_ip, sin_ip);
        importance *= std::max(cos_ip, 0.f);
    }
    return std::max(importance, 0.f);
}

}  // namespace neepp
