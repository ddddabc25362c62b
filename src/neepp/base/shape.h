// The shape interface: a surface of the scene, with its material and the area light it carries if it
// emits. Embree finds where rays meet shapes; a shape tells Embree what it is (embree_geometry), completes
// a hit into a SurfaceInteraction, and, if it can emit, samples points on itself by area.
//
// The built-in shapes are in shapes/: TriangleMesh (every mesh, and Mitsuba's rectangle, cube, disk and
// cylinder), Sphere, SdfGridShape and CurveShape. A new kind of surface that Embree can intersect through
// its user-geometry callbacks (as SdfGridShape does) implements this interface; a new shape that is a
// mesh needs only a loader plugin that returns the mesh (docs/extending.md).
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <embree3/rtcore.h>
#include "neepp/base/bsdf.h"
#include "neepp/base/interaction.h"
#include "neepp/base/light_bounds.h"
#include "neepp/math/bbox.h"
#include "neepp/math/transform.h"

namespace neepp {

class Light;
class Medium;

struct PositionSample {
    Vec3 p, n;      // point on the surface and its geometric normal
    Vec3 ns;        // its shading normal (a mesh's interpolated vertex normal; n where there is none)
    Vec2 uv;
    float pdf = 0;  // area density
};

// What a shape's geometry is, fed to a scene's fingerprint: a visibility map saved for one scene is then
// refused by another.
class GeometryDigest {
public:
    virtual void add(const void *data, size_t bytes) = 0;
    template <class T>
    void add(const T &value) {
        add(&value, sizeof value);
    }

protected:
    ~GeometryDigest() = default;
};

class Shape {
public:
    virtual ~Shape() = default;

    // --- What every shape defines.
    virtual BBox bounds() const = 0;
    // The shape as an Embree geometry on device (not yet committed; the scene commits and attaches it
    // under the shape's index, which hits report back). Null when there is nothing to intersect.
    virtual RTCGeometry embree_geometry(RTCDevice device) const = 0;
    // Completes a hit from what Embree reported: primitive prim, its hit coordinates (b1, b2) (a
    // triangle's barycentrics; what each shape's geometry reports) at distance t along ray. Sets p, t, n,
    // sh_frame, uv, dpdu, dpdv, shape and prim_index; the caller sets wi. dpdu and dpdv may be left zero
    // and the shading frame built from the normal alone when `tangents` is false.
    virtual void fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                                  SurfaceInteraction &si) const = 0;
    // Moves the shape by to_world (the loader applies a shape's own to_world and an instance's).
    virtual void transform(const Transform &to_world) = 0;
    // A copy, for the instances of a shape group.
    virtual std::unique_ptr<Shape> clone() const = 0;

    // --- What a shape that can carry an area light defines. An area of 0 means it cannot.
    virtual float area() const { return 0.f; }
    // A point by area, of density 1 / area (with_uv = false: the caller reads no uv, so it may be left
    // unset).
    virtual PositionSample sample_position(Vec2 u, bool with_uv = true) const { return {}; }
    // A cone holding the shading normals of every point (the light BVH's bound on where it emits).
    virtual DirectionCone normal_bounds() const { return DirectionCone::entire_sphere(); }

    // --- Optional.
    // Precomputation once the geometry is final (after every transform), before rendering.
    virtual void precompute() {}
    // Adds what the geometry is to a digest; the default adds the bounds and the area.
    virtual void digest(GeometryDigest &d) const;
    // For statistics.
    virtual size_t triangle_count() const { return 0; }

    // Called once by the scene when the geometry is final: reads what hits need from the material
    // (tangents, bsdf_flags), calls precompute() and keeps the area.
    void finalize();
    float surface_area() const { return area_; }
    float pdf_position() const { return area_ > 0 ? 1.f / area_ : 0.f; }

    std::string id;
    BSDFPtr bsdf;
    const Light *area_light = nullptr;  // set when the scene creates an area light for this shape
    bool flip_normals = false;
    // The media inside and outside it (null: vacuum), for a shape that bounds one: a ray leaving its
    // surface enters the interior where it goes against the geometric normal, the exterior along it.
    const Medium *interior = nullptr, *exterior = nullptr;
    bool is_medium_transition() const { return interior || exterior; }
    const Medium *medium_toward(const Vec3 &d, const Vec3 &n) const { return dot(d, n) > 0 ? exterior : interior; }
    // Set by finalize() from the BSDF: whether hits need dp/du, dp/dv and a shading frame aligned with dp/du
    // (Mitsuba's), or, when the BSDF reads neither (BSDF::needs_tangents), only a frame around the normal;
    // and the BSDF's flags, which the path tracer asks at every vertex.
    bool tangents = true;
    uint32_t bsdf_flags = 0;

protected:
    Shape() = default;
    Shape(const Shape &) = default;
    Shape &operator=(const Shape &) = default;

private:
    float area_ = 0;
};

}  // namespace neepp
