// A shape of the scene: a triangle mesh in world space (or an analytic sphere), its material, and the
// area light it carries if it emits.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include "neepp/materials/bsdf.h"
#include "neepp/math/bbox.h"
#include "neepp/math/distribution.h"
#include "neepp/scene/interaction.h"

namespace neepp {

class Light;

struct PositionSample {
    Vec3 p, n;      // point on the surface and its geometric normal
    Vec3 ns;        // its shading normal (the interpolated vertex normal; n without vertex normals)
    Vec2 uv;
    float pdf = 0;  // area density
};

struct Shape {
    enum class Kind { Mesh, Sphere };
    Kind kind = Kind::Mesh;
    std::string id;

    // Mesh data, world space. normals (per vertex) and uvs are empty when absent.
    std::vector<Vec3> positions, normals;
    std::vector<Vec2> uvs;
    std::vector<uint32_t> indices;
    bool face_normals = false;  // ignore vertex normals (Mitsuba's face_normals)
    bool flip_normals = false;

    // Sphere data.
    Vec3 center;
    float radius = 0;

    BSDFPtr bsdf;
    const Light *area_light = nullptr;  // set when the scene creates an area light for this shape
    // Hits carry dp/du, dp/dv and a shading frame aligned with dp/du (Mitsuba's), or, when the BSDF reads
    // neither (BSDF::needs_tangents), a frame built from the normal alone and no derivatives. finalize()
    // sets it from the BSDF.
    bool tangents = true;
    // bsdf->flags(), read once by finalize(): the path tracer asks at every vertex whether next event
    // estimation applies, and a wrapper's flags() is two virtual calls deep.
    uint32_t bsdf_flags = 0;

    // Call once after the geometry is final: computes the area, the triangle-area distribution and the
    // per-triangle records that hits (and, for emitters, light samples) read.
    void finalize();
    size_t triangle_count() const { return indices.size() / 3; }
    float surface_area() const { return area_; }
    BBox bounds() const;

    // Uniform sampling of a point by area.
    // with_uv = false leaves ps.uv unset (a caller with nothing textured to look up skips its fetch).
    PositionSample sample_position(Vec2 u, bool with_uv = true) const;
    float pdf_position() const { return area_ > 0 ? 1.f / area_ : 0.f; }

    // Completes a hit record from Embree's primitive index and barycentrics (or sphere hit).
    void fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                          SurfaceInteraction &si) const;
    // Cache prefetch of what fill_interaction(prim) reads: its triangle's record, two cache lines.
    // Inline: it runs once per ray, from the integrator's batch loop.
    void prefetch(uint32_t prim) const {
        if (kind == Kind::Sphere) return;
        const char *record = reinterpret_cast<const char *>(&hit_triangles_[prim]);
        __builtin_prefetch(record);
        __builtin_prefetch(record + sizeof(HitTriangle) - 1);
    }

private:
    // What a hit on one triangle reads, in one record: its corners, and its vertex normals and uvs where
    // the mesh has them. Through the index buffer, a hit read up to ten scattered cache lines (indices,
    // then three vertices in each of three arrays), most of them misses on a large scene, at a cost
    // close to the rest of the hit's shading; a record is two lines (32-byte aligned, 96 bytes).
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
    // A mesh of two triangles forming a parallelogram (Mitsuba's `rectangle`, a quad from a file) is
    // sampled as one: p = corner + u.x e1 + u.y e2, with no triangle to choose. Its uv is affine in
    // (u.x, u.y) when the corners' uvs form a parallelogram too (uv_affine), and then is what a ray hit
    // at p interpolates.
    struct Parallelogram {
        Vec3 p0, e1, e2, n;
        Vec2 uv0, duv1, duv2;
        bool uv_affine = false;
    };
    std::optional<Parallelogram> find_parallelogram() const;

    float area_ = 0;
    Distribution1D triangle_distribution_;
    std::vector<SamplingTriangle> sampling_triangles_;  // precomputed for emitters (sampled at every NEE)
    std::vector<HitTriangle> hit_triangles_;            // one per triangle, built by finalize()
    std::optional<Parallelogram> parallelogram_;
};

}  // namespace neepp
