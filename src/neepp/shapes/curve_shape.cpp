#include "neepp/shapes/curve_shape.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>


namespace neepp {
namespace {

// Mitsuba's curves cull back faces: no hit from inside a tube, so a ray leaving a curve's surface (or
// starting inside it) passes out of it unhit. Mitsuba builds Embree with that culling compiled in
// (EMBREE_BACKFACE_CULLING_CURVES); a system Embree may lack it, so this filter rejects every hit whose
// ray runs along the surface's outward normal. Where the culling is compiled in, it never sees one.
void cull_curve_back_faces(const RTCFilterFunctionNArguments *args) {
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const float along = RTCRayN_dir_x(args->ray, args->N, i) * RTCHitN_Ng_x(args->hit, args->N, i) +
                            RTCRayN_dir_y(args->ray, args->N, i) * RTCHitN_Ng_y(args->hit, args->N, i) +
                            RTCRayN_dir_z(args->ray, args->N, i) * RTCHitN_Ng_z(args->hit, args->N, i);
        if (along > 0) args->valid[i] = 0;
    }
}

}  // namespace

BBox CurveShape::bounds() const {
    // A segment's every point is a convex combination of its control points, each moved by its own radius.
    BBox b;
    for (const CurvePoint &cp : points) {
        b.expand(cp.p - Vec3(cp.radius));
        b.expand(cp.p + Vec3(cp.radius));
    }
    return b;
}

RTCGeometry CurveShape::embree_geometry(RTCDevice device) const {
    // No neighbour flags: linear segments are cones joined and ended by spheres, B-spline ones a sweep of
    // spheres with open ends; back faces culled as Mitsuba culls them.
    RTCGeometry geom = rtcNewGeometry(device, basis == CurveBasis::Linear ? RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE
                                                                          : RTC_GEOMETRY_TYPE_ROUND_BSPLINE_CURVE);
    auto *v = (CurvePoint *)rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                    sizeof(CurvePoint), points.size());
    std::copy(points.begin(), points.end(), v);
    auto *idx = (uint32_t *)rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t),
                                                    segments.size());
    std::copy(segments.begin(), segments.end(), idx);
    rtcSetGeometryIntersectFilterFunction(geom, cull_curve_back_faces);
    rtcSetGeometryOccludedFilterFunction(geom, cull_curve_back_faces);
    return geom;
}

void CurveShape::fill_interaction(uint32_t prim, float b1, float, const Ray &ray, float t, SurfaceInteraction &si) const {
    si.t = t;
    si.shape = this;
    si.prim_index = prim;
    si.p = ray.at(t);
    const CurveHit h = curve_hit(basis, &points[segments[prim]], prim, uint32_t(segments.size()), b1, si.p);
    si.n = h.n;
    si.uv = h.uv;
    if (tangents) {
        si.dpdu = h.dpdu, si.dpdv = h.dpdv;
        si.sh_frame = frame_along(h.n, h.dpdu);
    } else {
        si.dpdu = si.dpdv = Vec3(0.f);
        si.sh_frame = Frame(h.n);
    }
}

void CurveShape::transform(const Transform &to_world) {
    const float scale = uniform_scale(to_world, "the to_world of an instance of curves");
    for (CurvePoint &cp : points) {
        cp.p = to_world.point(cp.p);
        cp.radius *= scale;
        if (!is_finite(cp.p) || !std::isfinite(cp.radius))
            throw std::runtime_error("the transformed curve has non-finite control points");
    }
}

void CurveShape::digest(GeometryDigest &d) const {
    d.add("curves", 6);
    d.add(basis);
    d.add(points.data(), points.size() * sizeof(CurvePoint));
    d.add(segments.data(), segments.size() * sizeof(uint32_t));
}

}  // namespace neepp
