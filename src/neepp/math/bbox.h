// Axis-aligned bounding box.
#pragma once
#include "neepp/math/vec.h"

namespace neepp {

struct BBox {
    Vec3 lo{kInfinity}, hi{-kInfinity};
    void expand(const Vec3 &p) { lo = vmin(lo, p); hi = vmax(hi, p); }
    void expand(const BBox &b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
    bool valid() const { return lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z; }
    Vec3 extent() const { return hi - lo; }
    Vec3 center() const { return (lo + hi) * 0.5f; }
    bool contains(const Vec3 &p) const {
        return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
    }
};

}  // namespace neepp
