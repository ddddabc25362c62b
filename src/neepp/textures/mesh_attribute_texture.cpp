#include "neepp/textures/mesh_attribute_texture.h"

#include <stdexcept>
#include "neepp/shapes/triangle_mesh.h"

namespace neepp {

MeshAttributeTexture::MeshAttributeTexture(std::string name, float scale) : name_(std::move(name)), scale_(scale) {
    if (name_.rfind("vertex_", 0) != 0 && name_.rfind("face_", 0) != 0)
        throw std::invalid_argument("mesh attribute name must start with \"vertex_\" or \"face_\", not \"" + name_ + "\"");
}

namespace {

Color components(const MeshAttribute &a, size_t index) {
    const float *v = a.values.data() + index * size_t(a.dim);
    return a.dim == 1 ? Color(v[0]) : Color(v[0], v[1], v[2]);
}

}  // namespace

Color MeshAttributeTexture::eval(const SurfaceInteraction &si) const {
    // The loader checks that every shape this texture is used on is a mesh with the attribute.
    const auto *mesh = dynamic_cast<const TriangleMesh *>(si.shape);
    const MeshAttribute *a = mesh ? mesh->attribute(name_) : nullptr;
    if (!a) return Color(0.f);
    const size_t tri = si.prim_index;
    if (a->per_face()) return components(*a, tri) * scale_;
    // The hit's barycentric coordinates, recovered from its position on the (world-space) triangle.
    const uint32_t *idx = &mesh->indices[3 * tri];
    const Vec3 &p0 = mesh->positions[idx[0]];
    const Vec3 e1 = mesh->positions[idx[1]] - p0, e2 = mesh->positions[idx[2]] - p0, d = si.p - p0;
    const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), d1 = dot(d, e1), d2 = dot(d, e2);
    const float det = d11 * d22 - d12 * d12;
    if (!(det > 0)) return components(*a, idx[0]) * scale_;
    const float b1 = (d22 * d1 - d12 * d2) / det, b2 = (d11 * d2 - d12 * d1) / det;
    return (components(*a, idx[0]) * (1.f - b1 - b2) + components(*a, idx[1]) * b1 + components(*a, idx[2]) * b2) * scale_;
}

}  // namespace neepp
