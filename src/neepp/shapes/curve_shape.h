// Mitsuba 3's curves (`linearcurve`, `bsplinecurve`) as a shape: tubes of varying radius around centre
// lines (shapes/curve.h), which Embree intersects as its round curves. They have no area and cannot emit,
// as in Mitsuba, which cannot sample a point on them.
#pragma once
#include <vector>
#include "neepp/base/shape.h"
#include "neepp/shapes/curve.h"

namespace neepp {

class CurveShape final : public Shape {
public:
    // World space: the control points with their radii, and the first control point of each segment
    // (CurveData::segments).
    CurveBasis basis = CurveBasis::Linear;
    std::vector<CurvePoint> points;
    std::vector<uint32_t> segments;

    BBox bounds() const override;
    // Embree's round curves, set up as Mitsuba sets them up: b1 of a hit is the parameter along segment prim.
    RTCGeometry embree_geometry(RTCDevice device) const override;
    // Mitsuba's curves shade with the geometric normal, the frame's s around the tube.
    void fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                          SurfaceInteraction &si) const override;
    // An instance's to_world (a curve shape's own to_world moves the points and leaves the radii, as
    // Mitsuba's): may translate, rotate, mirror and scale uniformly, the radii scaling with it.
    void transform(const Transform &to_world) override;
    std::unique_ptr<Shape> clone() const override { return std::make_unique<CurveShape>(*this); }
    void digest(GeometryDigest &d) const override;
};

}  // namespace neepp
