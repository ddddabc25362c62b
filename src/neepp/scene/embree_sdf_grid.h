// An SDF grid shape as Embree user geometry: one primitive per voxel that holds surface, bounded by its
// box around the surface, intersected by SdfGrid::intersect, as Mitsuba 3 hands its sdfgrid to Embree.
#pragma once
#include <embree3/rtcore.h>

namespace neepp {

struct Shape;

// A geometry for the shape (kind SdfGrid, finalized), to commit; the shape must outlive it, as the
// callbacks read it. Hits report the voxel as the primitive, u = v = 0, and the ray's t.
RTCGeometry new_sdf_grid_geometry(RTCDevice device, const Shape &shape);

}  // namespace neepp
