#include "neepp/shapes/curve.h"

#include <cmath>
#include "neepp/math/frame.h"

namespace neepp {

CurveSample eval_curve_segment(CurveBasis basis, const CurvePoint *cp, float v) {
    CurveSample s;
    if (basis == CurveBasis::Linear) {
        s.c = cp[0].p * (1.f - v) + cp[1].p * v;
        s.dc = cp[1].p - cp[0].p;
        s.r = cp[0].radius * (1.f - v) + cp[1].radius * v;
        s.dr = cp[1].radius - cp[0].radius;
        return s;
    }
    // The uniform cubic B-spline's basis functions and their first three derivatives at v.
    const float w = 1.f - v, v2 = v * v, v3 = v2 * v;
    const float b[4] = {w * w * w / 6.f, (3.f * v3 - 6.f * v2 + 4.f) / 6.f, (-3.f * v3 + 3.f * v2 + 3.f * v + 1.f) / 6.f,
                        v3 / 6.f};
    const float db[4] = {-0.5f * w * w, 1.5f * v2 - 2.f * v, -1.5f * v2 + v + 0.5f, 0.5f * v2};
    const float ddb[4] = {w, 3.f * v - 2.f, 1.f - 3.f * v, v};
    const float dddb[4] = {-1.f, 3.f, -3.f, 1.f};
    for (int k = 0; k < 4; ++k) {
        s.c += cp[k].p * b[k];
        s.dc += cp[k].p * db[k];
        s.dcc += cp[k].p * ddb[k];
        s.dccc += cp[k].p * dddb[k];
        s.r += cp[k].radius * b[k];
        s.dr += cp[k].radius * db[k];
    }
    return s;
}

void curve_cross_frame(const Vec3 &tangent, Vec3 &rot, Vec3 &rad) {
    const Vec3 guide(0, 0, 1);
    const Vec3 across = guide - tangent * dot(tangent, guide);
    const float len2 = squared_norm(across);
    rot = std::abs(dot(tangent, guide)) == 1.f || !(len2 > 0) ? Vec3(0, 1, 0) : across / std::sqrt(len2);
    rad = cross(rot, tangent);
}

namespace {

// How the direction `dir` across a B-spline tube (unit, perpendicular to the tangent) turns as v runs
// along the segment with its angle to the curve's Frenet frame held fixed: d dir / dv. Mitsuba's dp/dv
// on its B-spline curves uses this (where the frame is undefined, on straight stretches, it is zero).
Vec3 frenet_turn(const CurveSample &s, const Vec3 &tangent, const Vec3 &dir) {
    const float speed = norm(s.dc);
    const Vec3 binormal_dir = cross(s.dc, s.dcc);
    const float bn = norm(binormal_dir);
    const float kappa = bn / (speed * speed * speed);
    if (!(kappa >= 0x1p-24f) || !std::isfinite(kappa)) return Vec3(0.f);
    float tau = dot(s.dccc, binormal_dir) / (bn * bn);
    if (bn < 1e-6f || norm(s.dccc) < 1e-6f) tau = 0.f;
    const Vec3 normal = normalize(cross(binormal_dir, s.dc)), binormal = normalize(cross(tangent, normal));
    const float cos_t = dot(normal, dir), sin_t = dot(binormal, dir);
    // Frenet-Serret: dN/ds = -kappa T + tau B, dB/ds = -tau N, and ds/dv = |dc/dv|.
    return (tangent * (-kappa * cos_t) + binormal * (tau * cos_t) - normal * (tau * sin_t)) * speed;
}

}  // namespace

CurveHit curve_hit(CurveBasis basis, const CurvePoint *segment, uint32_t index, uint32_t segment_count, float v,
                   const Vec3 &p) {
    const CurveSample s = eval_curve_segment(basis, segment, v);
    const Vec3 tangent = normalize(s.dc);
    const Vec3 offset = p - s.c;
    CurveHit h;
    if (basis == CurveBasis::Linear) {
        h.n = normalize(offset);
    } else {
        // The sweep of spheres' normal at p: the offset, corrected for the centre line's curvature and
        // the radius' change along it.
        h.n = normalize(offset * (squared_norm(s.dc) - dot(offset, s.dcc)) - s.dc * (s.dr * s.r));
    }
    // u: the angle around the tube in the cross frame; v: the position along all the file's segments.
    Vec3 rot, rad;
    curve_cross_frame(tangent, rot, rad);
    const Vec3 dir = normalize(offset);
    const float a = dot(rad, dir), b = dot(rot, dir);
    float angle = std::atan2(b, a);
    if (angle < 0) angle += 2.f * kPi;
    h.uv = Vec2(angle * kInv2Pi, (v + float(index)) / float(segment_count));
    if (basis == CurveBasis::Linear) {
        h.dpdu = cross(tangent, offset) * (2.f * kPi);
        h.dpdv = (s.dc + dir * s.dr) * float(segment_count);
    } else {
        // The direction across the tube at angle u (dir without its component along the tangent).
        const float ab = std::sqrt(a * a + b * b);
        const Vec3 across = ab > 0 ? (rad * a + rot * b) / ab : rad;
        h.dpdu = cross(tangent, across) * (2.f * kPi * s.r);
        h.dpdv = (s.dc + across * s.dr + frenet_turn(s, tangent, across) * s.r) * float(segment_count);
    }
    return h;
}

}  // namespace neepp
