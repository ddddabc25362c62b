// What a triangle mesh costs in memory: Embree reads the mesh's own vertex and index arrays (no copies),
// and the mesh keeps no per-triangle record beyond its index triple and its triangle-area distribution
// (an emitter's adds its sampling records), so a large mesh holds about 36 bytes a triangle, Embree's
// BVH aside.
#include <gtest/gtest.h>

#include <embree3/rtcore.h>
#include <memory>

#include "neepp/materials/diffuse.h"
#include "neepp/shapes/triangle_mesh.h"

using namespace neepp;

namespace {

// A height field of n x n quads (2 n^2 triangles) with vertex normals and no texture coordinates, as a PLY
// terrain becomes once loaded (the loader computes the normals a file lacks).
std::unique_ptr<TriangleMesh> grid(int n) {
    auto s = std::make_unique<TriangleMesh>();
    for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
            s->positions.push_back(Vec3(float(i), 0.1f * float((i * 7 + j * 3) % 5), float(j)));
            s->normals.push_back(Vec3(0, 1, 0));
        }
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const uint32_t a = uint32_t(i * (n + 1) + j), b = a + uint32_t(n + 1);
            s->indices.insert(s->indices.end(), {a, b, b + 1, a, b + 1, a + 1});
        }
    // As a reader leaves them: no growth slack. And no spare position either: precompute must make room for
    // Embree's padding.
    s->positions.shrink_to_fit();
    s->normals.shrink_to_fit();
    s->indices.shrink_to_fit();
    s->bsdf = std::make_shared<DiffuseBSDF>(constant_texture(Color(0.5f)));
    return s;
}

struct Device {
    RTCDevice device = rtcNewDevice(nullptr);
    ~Device() { rtcReleaseDevice(device); }
};

}  // namespace

TEST(MeshMemory, EmbreeSharesTheMeshArrays) {
    Device d;
    ASSERT_NE(d.device, nullptr);
    auto mesh = grid(8);
    const std::unique_ptr<Shape> copy = mesh->clone();  // a copy (an instance's) has no spare capacity either
    for (Shape *s : {static_cast<Shape *>(mesh.get()), copy.get()}) {
        auto &m = static_cast<TriangleMesh &>(*s);
        m.finalize();
        ASSERT_GT(m.positions.capacity(), m.positions.size());  // room for Embree's 16-byte load of the last vertex
        RTCGeometry geom = m.embree_geometry(d.device);
        ASSERT_NE(geom, nullptr);
        EXPECT_EQ(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0), static_cast<const void *>(m.positions.data()));
        EXPECT_EQ(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_INDEX, 0), static_cast<const void *>(m.indices.data()));
        rtcReleaseGeometry(geom);
        EXPECT_EQ(rtcGetDeviceError(d.device), RTC_ERROR_NONE);
    }
}

TEST(MeshMemory, NoPerTriangleRecordBeyondIndicesAndAreaTable) {
    auto mesh = grid(100);
    mesh->finalize();
    const double per_triangle = double(mesh->memory_bytes()) / double(mesh->triangle_count());
    // Positions and normals (about 6 bytes a triangle each: a vertex per two triangles), indices (12),
    // the area distribution's weight and cumulative sum (4 + 8).
    EXPECT_LT(per_triangle, 40.0);
    EXPECT_GT(per_triangle, 30.0);  // the accounting sees the arrays
}
