// Mitsuba 3's `sdfgrid` shape: an SdfGrid (shapes/sdf_grid.h) placed in the world by an affine to_world.
// Embree intersects it as user geometry: one primitive per voxel that holds surface, bounded by its box
// around the surface, intersected by SdfGrid::intersect in the grid's space, as Mitsuba 3 hands its
// sdfgrid to Embree. It has no area (Mitsuba's sdfgrid cannot emit) and no uv (0, 0 as in Mitsuba).
#pragma once
#include <memory>
#include "neepp/base/shape.h"
#include "neepp/shapes/sdf_grid.h"

namespace neepp {

class SdfGridShape final : public Shape {
public:
    // The grid in its own space [0, 1]^3, shared by the instances of one shape, and where to_world puts it.
    std::shared_ptr<const SdfGrid> grid;
    Transform to_world;

    BBox bounds() const override;
    // Hits report the voxel as the primitive, u = v = 0, and the ray's t. The shape must outlive the
    // geometry, whose callbacks read it.
    RTCGeometry embree_geometry(RTCDevice device) const override;
    // Mitsuba's normals at the hit: the geometric normal the gradient of the hit voxel's interpolant, the
    // shading normal by the grid's `normals` option, both moved by to_world as normals are; no uv or dp/du.
    void fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                          SurfaceInteraction &si) const override;
    // Any affine to_world: rays go to the grid's space.
    void transform(const Transform &to_world) override;
    std::unique_ptr<Shape> clone() const override { return std::make_unique<SdfGridShape>(*this); }
    void precompute() override { to_object_ = to_world.inverse(); }
    void digest(GeometryDigest &d) const override;

    // to_world's inverse, which every ray against the grid goes through; set by precompute().
    const Transform &to_object() const { return to_object_; }

private:
    Transform to_object_;
};

}  // namespace neepp
