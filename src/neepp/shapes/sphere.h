// Mitsuba 3's analytic `sphere`, which Embree intersects as a sphere primitive.
#pragma once
#include "neepp/base/shape.h"

namespace neepp {

class Sphere final : public Shape {
public:
    Vec3 center;
    float radius = 1;
    // The world directions of the sphere's own x, y and z, which its uv and dp/du follow (Mitsuba's are
    // in the frame its to_world rotates).
    Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

    BBox bounds() const override;
    RTCGeometry embree_geometry(RTCDevice device) const override;
    // Mitsuba's uv: (phi / 2pi, theta / pi) in the sphere's frame, with its partials dp/du (around the z
    // axis) and dp/dv (toward -z).
    void fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                          SurfaceInteraction &si) const override;
    // May translate, rotate, mirror and scale uniformly (the axes turn with it, the radius scales with
    // it); Mitsuba allows more, neepp refuses it.
    void transform(const Transform &to_world) override;
    std::unique_ptr<Shape> clone() const override { return std::make_unique<Sphere>(*this); }
    float area() const override { return 4.f * kPi * radius * radius; }
    PositionSample sample_position(Vec2 u, bool with_uv = true) const override;
    void digest(GeometryDigest &d) const override;
};

}  // namespace neepp
