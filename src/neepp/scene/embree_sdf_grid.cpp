#include "neepp/scene/embree_sdf_grid.h"

#include <limits>
#include "neepp/scene/sdf_grid.h"
#include "neepp/scene/shape.h"

namespace neepp {

namespace {

void bounds(const RTCBoundsFunctionArguments *args) {
    const Shape &shape = *static_cast<const Shape *>(args->geometryUserPtr);
    const BBox &local = shape.sdf_grid->surface_bounds(args->primID);
    BBox world;
    for (int k = 0; k < 8; ++k)
        world.expand(shape.sdf_to_world.point({k & 1 ? local.hi.x : local.lo.x, k & 2 ? local.hi.y : local.lo.y,
                                          k & 4 ? local.hi.z : local.lo.z}));
    RTCBounds &b = *args->bounds_o;
    b.lower_x = world.lo.x, b.lower_y = world.lo.y, b.lower_z = world.lo.z;
    b.upper_x = world.hi.x, b.upper_y = world.hi.y, b.upper_z = world.hi.z;
}

// Ray i of a packet of N (N = 1 for single rays) against the voxel: its t if it meets the surface within
// [tnear, tfar].
bool hit_lane(const Shape &shape, unsigned prim, RTCRayN *ray, unsigned N, unsigned i, float &t) {
    const Vec3 o(RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i));
    const Vec3 d(RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i));
    const Transform &to_object = shape.sdf_to_object();
    return shape.sdf_grid->intersect(prim, to_object.point(o), to_object.vector(d), RTCRayN_tnear(ray, N, i),
                                     RTCRayN_tfar(ray, N, i), t);
}

void intersect(const RTCIntersectFunctionNArguments *args) {
    const Shape &shape = *static_cast<const Shape *>(args->geometryUserPtr);
    RTCRayN *ray = RTCRayHitN_RayN(args->rayhit, args->N);
    RTCHitN *hit = RTCRayHitN_HitN(args->rayhit, args->N);
    for (unsigned i = 0; i < args->N; ++i) {
        float t;
        if (!args->valid[i] || !hit_lane(shape, args->primID, ray, args->N, i, t)) continue;
        RTCRayN_tfar(ray, args->N, i) = t;
        RTCHitN_u(hit, args->N, i) = 0.f;
        RTCHitN_v(hit, args->N, i) = 0.f;
        RTCHitN_Ng_x(hit, args->N, i) = 0.f;  // unused: the hit record computes its normal from the grid
        RTCHitN_Ng_y(hit, args->N, i) = 0.f;
        RTCHitN_Ng_z(hit, args->N, i) = 0.f;
        RTCHitN_primID(hit, args->N, i) = args->primID;
        RTCHitN_geomID(hit, args->N, i) = args->geomID;
        RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
    }
}

void occluded(const RTCOccludedFunctionNArguments *args) {
    const Shape &shape = *static_cast<const Shape *>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        float t;
        if (args->valid[i] && hit_lane(shape, args->primID, args->ray, args->N, i, t))
            RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
    }
}

}  // namespace

RTCGeometry new_sdf_grid_geometry(RTCDevice device, const Shape &shape) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, unsigned(shape.sdf_grid->voxel_count()));
    rtcSetGeometryUserData(geom, const_cast<Shape *>(&shape));
    rtcSetGeometryBoundsFunction(geom, bounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, intersect);
    rtcSetGeometryOccludedFunction(geom, occluded);
    return geom;
}

}  // namespace neepp
