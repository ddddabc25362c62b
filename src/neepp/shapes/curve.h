// Mitsuba 3's curves (`linearcurve`, `bsplinecurve`): tubes of varying radius around a centre line,
// which Embree intersects as its round curves. What is here completes a hit from the segment Embree
// reports and the curve parameter along it, as Mitsuba's shapes do: the normal, the uv parameterization
// (u around the tube, v along all segments of the file) and its derivatives.
#pragma once
#include <cstdint>
#include "neepp/io/curve_reader.h"
#include "neepp/math/vec.h"

namespace neepp {

// A control point in Embree's layout (RTC_FORMAT_FLOAT4: x, y, z, radius).
struct CurvePoint {
    Vec3 p;
    float radius = 0;
};
static_assert(sizeof(CurvePoint) == 16);

// The centre line and radius of one segment at its parameter v in [0, 1], with their derivatives by v.
struct CurveSample {
    Vec3 c, dc, dcc, dccc;  // centre, its first, second and third derivatives
    float r = 0, dr = 0;    // radius and its derivative
};
// segment: its first control point (points_per_segment(basis) of them follow in order).
CurveSample eval_curve_segment(CurveBasis basis, const CurvePoint *segment, float v);

// Mitsuba's frame across the tube, from which u is measured: rot is the world +z made perpendicular to
// the unit tangent (+y where the tangent is along z), rad = rot x tangent; u = 0 lies along rad and
// u = 1/4 along rot.
void curve_cross_frame(const Vec3 &tangent, Vec3 &rot, Vec3 &rad);

struct CurveHit {
    Vec3 n;           // the tube's unit outward normal
    Vec2 uv;
    Vec3 dpdu, dpdv;  // position derivatives by u and v
};
// A hit at p on segment `index` of segment_count, at curve parameter v (Embree's hit u). For a linear
// segment Embree's v already accounts for the change of radius, so the normal is p minus the centre there.
CurveHit curve_hit(CurveBasis basis, const CurvePoint *segment, uint32_t index, uint32_t segment_count, float v,
                   const Vec3 &p);

}  // namespace neepp
