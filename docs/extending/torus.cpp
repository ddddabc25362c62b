// A shape: a torus around the z axis, as a triangle mesh. A shape plugin makes the mesh in its own space;
// the loader places it by to_world, gives it its BSDF and area emitter, and traces it with Embree as it does
// every mesh (a shape that is not a mesh, as sphere is, implements base/shape.h's interface).
#include <cmath>
#include "neepp/loader/plugins.h"

namespace example {
using namespace neepp;

// major: the radius of the circle the tube's centre follows; minor: the tube's. Vertices on a grid of
// (u around the axis, v around the tube), with the tube's normals and (u, v) as texture coordinates.
MeshData torus_mesh(float major, float minor, int segments, int sides) {
    MeshData m;
    for (int i = 0; i <= segments; ++i)
        for (int j = 0; j <= sides; ++j) {
            const float u = float(i) / float(segments), v = float(j) / float(sides);
            const float phi = 2.f * kPi * u, theta = 2.f * kPi * v;
            const Vec3 ring(std::cos(phi), std::sin(phi), 0.f);  // toward the tube's centre
            const Vec3 n = ring * std::cos(theta) + Vec3(0, 0, std::sin(theta));
            m.positions.push_back(ring * major + n * minor);
            m.normals.push_back(n);
            m.uvs.push_back(Vec2(u, v));
        }
    const auto at = [&](int i, int j) { return uint32_t(i * (sides + 1) + j); };
    for (int i = 0; i < segments; ++i)
        for (int j = 0; j < sides; ++j)  // counter-clockwise seen from outside: the normals point out
            for (uint32_t k : {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)})
                m.indices.push_back(k);
    return m;
}

// <shape type="torus"><float name="major_radius" value="1"/><float name="minor_radius" value="0.25"/></shape>
void register_torus() {
    register_shape("torus", [](const PluginProperties &props) {
        const float major = props.node.get_float("major_radius", 1.f), minor = props.node.get_float("minor_radius", 0.25f);
        if (!(major > 0.f && minor > 0.f && minor < major))
            throw props.error("a torus needs 0 < minor_radius < major_radius");
        const int segments = props.node.get_int("segments", 96), sides = props.node.get_int("sides", 32);
        if (segments < 3 || sides < 3 || segments > 4096 || sides > 4096)
            throw props.error("segments and sides must be in [3, 4096]");
        return torus_mesh(major, minor, segments, sides);
    });
}

}  // namespace example
