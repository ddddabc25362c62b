// The uv parameterisation of Mitsuba's analytic `disk` and `cylinder`, which neepp traces as fine meshes
// (loader/shapes.cpp): a hit on the mesh takes the uv, dp/du, dp/dv and shading normal that Mitsuba's
// analytic shape gives the same point. A mesh's own, interpolated across each facet, is close in uv but
// not in the partials (a disk fan's dp/dv is 2π wherever the hit lies, Mitsuba's 2π r), and the partials
// are what a bump map tilts the normal by.
#pragma once
#include <cstdint>
#include "neepp/math/transform.h"
#include "neepp/math/vec.h"

namespace neepp {

struct AnalyticUv {
    enum class Surface : uint8_t {
        Disk,      // the unit disk in z = 0: uv = (r, φ / 2π), dp/du radial, dp/dv = 2π r along φ
        Cylinder,  // radius 1 about z, from z = 0 to 1: uv = (φ / 2π, z), dp/du = 2π along φ, dp/dv = z
    };
    Surface surface = Surface::Disk;
    Transform to_world;  // from the shape's own space, where it is the unit surface above

    struct Partials {
        Vec2 uv;
        Vec3 dpdu, dpdv;
        Vec3 n;  // the outward unit normal of the analytic surface (not flipped)
    };
    // At world point p of the mesh, which lies on (or, between a facet's corners, just inside) the surface.
    Partials at(const Vec3 &p) const;
};

}  // namespace neepp
