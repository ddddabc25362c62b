#include "neepp/base/shape.h"

namespace neepp {

void Shape::finalize() {
    tangents = !bsdf || bsdf->needs_tangents();
    bsdf_flags = bsdf ? bsdf->flags() : 0;
    precompute();
    area_ = area();
}

void Shape::digest(GeometryDigest &d) const {
    const BBox b = bounds();
    d.add(b.lo);
    d.add(b.hi);
    d.add(area());
}

}  // namespace neepp
