// A triangle mesh in world space: every mesh file (obj, ply, serialized), Mitsuba's rectangle, cube, disk
// and cylinder, and the meshes of shape plugins.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include "neepp/base/shape.h"
#include "neepp/io/mesh_data.h"
#include "neepp/math/distribution.h"
#include "neepp/shapes/analytic_uv.h"

namespace neepp {

struct HitLanes;

class TriangleMesh final : public Shape {
public:
    // World space. normals (per vertex) and uvs are empty when absent.
    std::vector<Vec3> positions, normals;
    std::vector<Vec2> uvs;
    std::vector<uint32_t> indices;
    // Per-vertex and per-face attributes (of a PLY file), shared by the instances of one mesh.
    std::shared_ptr<const std::vector<MeshAttribute>> attributes;
    bool face_normals = false;  // ignore vertex normals (Mitsuba's face_normals)
    // Set for the mesh of one of Mitsuba's analytic shapes (disk, cylinder): hits and sampled points take
    // that shape's uv, partials and shading normal instead of the mesh's interpolated ones. transform()
    // moves it with the mesh.
    std::optional<AnalyticUv> analytic_uv;

    BBox bounds() const override;
    RTCGeometry embree_geometry(RTCDevice device) const override;
    void fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                          SurfaceInteraction &si) const override;
    // Vertex normals keep their direction relative to the surface (the inverse transpose, renormalized).
    void transform(const Transform &to_world) override;
    std::unique_ptr<Shape> clone() const override { return std::make_unique<TriangleMesh>(*this); }
    float area() const override { return area_; }
    // A triangle chosen by area, then a point uniformly on it; a parallelogram as one.
    PositionSample sample_position(Vec2 u, bool with_uv = true) const override;
    // The union of the face normals and the vertex normals (flipped if asked): the shading normals, which
    // decide the emission side, lie between a face's vertex normals.
    DirectionCone normal_bounds() const override;
    // The area, the triangle-area distribution and the per-triangle records that hits (and, for
    // emitters, light samples) read.
    void precompute() override;
    void digest(GeometryDigest &d) const override;
    size_t triangle_count() const override { return indices.size() / 3; }

    // The attribute of that name, null when the mesh has none.
    const MeshAttribute *attribute(const std::string &name) const {
        if (attributes)
            for (const MeshAttribute &a : *attributes)
                if (a.name == name) return &a;
        return nullptr;
    }

    // A mesh of two triangles forming a parallelogram (Mitsuba's `rectangle`, a quad from a file) is
    // sampled as one: p = corner + u.x e1 + u.y e2, with no triangle to choose. Its uv is affine in
    // (u.x, u.y) when the corners' uvs form a parallelogram too (uv_affine), and then is what a ray hit
    // at p interpolates.
    struct Parallelogram {
        Vec3 p0, e1, e2, n;
        Vec2 uv0, duv1, duv2;
        bool uv_affine = false;
    };
    // This mesh as a parallelogram (its normal flipped if asked), if it is one: light samples in lanes
    // (LightSampleLanes) take it from here.
    const std::optional<Parallelogram> &parallelogram() const { return parallelogram_; }

    // --- For the path tracer's fast form.
    // Whether its hits may be filled eight at a time (shapes/hit_lanes.h): a mesh whose BSDF needs no
    // tangents, which is most of every scene's hits.
    // Not an analytic shape's, whose uv the lanes would interpolate.
    bool fills_in_lanes() const { return !tangents && !analytic_uv; }
    // Cache prefetch of what fill_interaction(prim) reads: its triangle's record, two cache lines.
    // Inline: it runs once per ray, from the integrator's batch loop.
    void prefetch(uint32_t prim) const {
        const char *record = reinterpret_cast<const char *>(&hit_triangles_[prim]);
        __builtin_prefetch(record);
        __builtin_prefetch(record + sizeof(HitTriangle) - 1);
    }

private:
    friend void add_lane(HitLanes &h, const TriangleMesh &mesh, uint32_t prim, float b1, float b2, float t,
                         const Vec3 &d, SurfaceInteraction &out);
    // What a hit on one triangle reads, in one record: its corners, and its vertex normals and uvs where
    // the mesh has them. Through the index buffer, a hit reads up to ten scattered cache lines (indices,
    // then three vertices in each of three arrays), most of them misses on a large scene; a record is two
    // lines (32-byte aligned, 96 bytes).
    struct alignas(32) HitTriangle {
        Vec3 p[3], n[3];
        Vec2 uv[3];
    };
    static_assert(sizeof(HitTriangle) == 96);
    // The interpolated vertex normal at barycentrics (b0, b1, b2), or the face normal ng (already flipped).
    Vec3 shading_normal(const HitTriangle &tri, float b0, float b1, float b2, const Vec3 &ng) const;
    // What sampling a point on one triangle reads: a corner, the two edges from it and the unit face
    // normal (flipped if asked), one 48-byte record instead of three indices, three vertices and a
    // normalization per light sample.
    struct SamplingTriangle {
        Vec3 p0, e1, e2, n;
    };
    SamplingTriangle sampling_triangle(size_t tri) const;
    std::optional<Parallelogram> find_parallelogram() const;

    float lane_flip_ = 0, lane_vertex_normals_ = 0, lane_has_uv_ = 0;  // HitLanes' masks, set by precompute()
    float area_ = 0;
    Distribution1D triangle_distribution_;
    std::vector<SamplingTriangle> sampling_triangles_;  // precomputed for emitters (sampled at every NEE)
    std::vector<HitTriangle> hit_triangles_;            // one per triangle, built by precompute()
    std::optional<Parallelogram> parallelogram_;
};

}  // namespace neepp
