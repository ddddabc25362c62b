// Triangle hits filled eight at a time, in lanes (hit_lanes.cpp), for the path tracer's fast form: as
// TriangleMesh::fill_interaction and then wi = to_local(-d) would fill them, one per lane, in SoA.
#pragma once
#include "neepp/shapes/triangle_mesh.h"

namespace neepp {

// What each lane's hit record is computed from.
struct HitLanes {
    static constexpr int kLanes = 8;
    alignas(32) float b1[kLanes], b2[kLanes], t[kLanes];  // barycentrics, ray distance
    alignas(32) float dx[kLanes], dy[kLanes], dz[kLanes];  // ray direction
    // The shape's options, as masks the kernel applies: -0 flips the normals (+0 not); all bits set where
    // the mesh has vertex normals to interpolate (and face_normals is off) / texture coordinates.
    alignas(32) float flip[kLanes], vertex_normals[kLanes], has_uv[kLanes];
    const float *tri[kLanes];  // the triangle's record (TriangleMesh::HitTriangle)
    const TriangleMesh *shape[kLanes];
    uint32_t prim[kLanes];
    SurfaceInteraction *out[kLanes];
    int n = 0;  // lanes in use
};

// Fills the queued hits and empties the lanes. The kernel costs as much for one lane as for eight, but
// filling the last few of a batch one at a time saves nothing, and each lane's result depends on nothing
// else: a path gets the same hit records, so the same image to the bit, whether it is traced alone or with
// others.
void fill_lanes(HitLanes &h);

// Queues a hit on triangle prim of shape (shape.fills_in_lanes() must hold); the eighth fills all of them.
inline void add_lane(HitLanes &h, const TriangleMesh &shape, uint32_t prim, float b1, float b2, float t, const Vec3 &d,
                     SurfaceInteraction &out) {
    const int i = h.n++;
    h.tri[i] = reinterpret_cast<const float *>(&shape.hit_triangles_[prim]);
    h.b1[i] = b1, h.b2[i] = b2, h.t[i] = t;
    h.dx[i] = d.x, h.dy[i] = d.y, h.dz[i] = d.z;
    h.flip[i] = shape.lane_flip_, h.vertex_normals[i] = shape.lane_vertex_normals_, h.has_uv[i] = shape.lane_has_uv_;
    h.shape[i] = &shape, h.prim[i] = prim, h.out[i] = &out;
    if (h.n == HitLanes::kLanes) fill_lanes(h);
}

}  // namespace neepp
