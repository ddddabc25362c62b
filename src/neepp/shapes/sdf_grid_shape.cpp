#include "neepp/shapes/sdf_grid_shape.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace neepp {

namespace {

void sdf_bounds(const RTCBoundsFunctionArguments *args) {
    const SdfGridShape &shape = *static_cast<const SdfGridShape *>(args->geometryUserPtr);
    const BBox &local = shape.grid->surface_bounds(args->primID);
    BBox world;
    for (int k = 0; k < 8; ++k)
        world.expand(shape.to_world.point({k & 1 ? local.hi.x : local.lo.x, k & 2 ? local.hi.y : local.lo.y,
                                          k & 4 ? local.hi.z : local.lo.z}));
    RTCBounds &b = *args->bounds_o;
    b.lower_x = world.lo.x, b.lower_y = world.lo.y, b.lower_z = world.lo.z;
    b.upper_x = world.hi.x, b.upper_y = world.hi.y, b.upper_z = world.hi.z;
}

// Ray i of a packet of N (N = 1 for single rays) against the voxel: its t if it meets the surface within
// [tnear, tfar].
bool hit_lane(const SdfGridShape &shape, unsigned prim, RTCRayN *ray, unsigned N, unsigned i, float &t) {
    const Vec3 o(RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i));
    const Vec3 d(RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i));
    const Transform &to_object = shape.to_object();
    return shape.grid->intersect(prim, to_object.point(o), to_object.vector(d), RTCRayN_tnear(ray, N, i),
                                     RTCRayN_tfar(ray, N, i), t);
}

void intersect(const RTCIntersectFunctionNArguments *args) {
    const SdfGridShape &shape = *static_cast<const SdfGridShape *>(args->geometryUserPtr);
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
    const SdfGridShape &shape = *static_cast<const SdfGridShape *>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        float t;
        if (args->valid[i] && hit_lane(shape, args->primID, args->ray, args->N, i, t))
            RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
    }
}

}  // namespace

BBox SdfGridShape::bounds() const {
    BBox b;
    for (int k = 0; k < 8; ++k) b.expand(to_world.point(Vec3(float(k & 1), float(k >> 1 & 1), float(k >> 2 & 1))));
    return b;
}

RTCGeometry SdfGridShape::embree_geometry(RTCDevice device) const {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, unsigned(grid->voxel_count()));
    rtcSetGeometryUserData(geom, const_cast<SdfGridShape *>(this));
    rtcSetGeometryBoundsFunction(geom, sdf_bounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, intersect);
    rtcSetGeometryOccludedFunction(geom, occluded);
    return geom;
}

void SdfGridShape::fill_interaction(uint32_t prim, float, float, const Ray &ray, float t, SurfaceInteraction &si) const {
    si.t = t;
    si.shape = this;
    si.prim_index = prim;
    si.p = ray.at(t);
    const Vec3 local = to_object_.point(si.p);
    // A gradient of zero (a flat spot of a degenerate grid) has no direction: the side the ray came from.
    auto world_normal = [&](const Vec3 &n, const Vec3 &fallback) {
        const Vec3 w = to_world.normal(n);
        const float len = norm(w);
        return len > 0 && std::isfinite(len) ? w / len : fallback;
    };
    si.n = world_normal(grid->gradient(local), -normalize(ray.d));
    si.sh_frame = Frame(world_normal(grid->shading_normal(local), si.n));
    si.uv = Vec2(0.f, 0.f);
    si.dpdu = si.dpdv = Vec3(0.f);
}

void SdfGridShape::transform(const Transform &m) {
    to_world = m * to_world;
    for (const auto &row : to_world.matrix.m)
        for (float v : row)
            if (!std::isfinite(v)) throw std::runtime_error("the sdfgrid's to_world is not finite");
}

void SdfGridShape::digest(GeometryDigest &d) const {
    d.add("sdfgrid", 7);
    const uint32_t dims[3] = {grid->size(0), grid->size(1), grid->size(2)};
    d.add(dims);
    d.add(grid->values().data(), grid->values().size() * sizeof(float));
    d.add(to_world.matrix);
}

}  // namespace neepp
