// A shape of the scene: a triangle mesh in world space (or an analytic sphere, an SDF grid, or curves),
// its material, and the area light it carries if it emits.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include "neepp/base/bsdf.h"
#include "neepp/base/interaction.h"
#include "neepp/io/mesh_data.h"
#include "neepp/math/bbox.h"
#include "neepp/math/distribution.h"
#include "neepp/math/transform.h"
#include "neepp/scene/curve.h"

namespace neepp {

class Light;
class SdfGrid;

struct HitLanes;

struct PositionSample {
    Vec3 p, n;      // point on the surface and its geometric normal
    Vec3 ns;        // its shading normal (the interpolated vertex normal; n without vertex normals)
    Vec2 uv;
    float pdf = 0;  // area density
};

struct Shape {
    enum class Kind { Mesh, Sphere, SdfGrid, Curve };
    Kind kind = Kind::Mesh;
    std::string id;

    // Mesh data, world space. normals (per vertex) and uvs are empty when absent.
    std::vector<Vec3> positions, normals;
    std::vector<Vec2> uvs;
    std::vector<uint32_t> indices;
    // Per-vertex and per-face attributes (of a PLY file), shared by the instances of one mesh.
    std::shared_ptr<const std::vector<MeshAttribute>> attributes;
    bool face_normals = false;  // ignore vertex normals (Mitsuba's face_normals)
    bool flip_normals = false;

    // Sphere data. The axes are the world directions of the sphere's own x, y and z, which its uv and
    // dp/du follow (Mitsuba's are in the frame its to_world rotates).
    Vec3 center;
    float radius = 0;
    Vec3 sphere_axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

    // SDF grid data: the grid in its own space [0, 1]^3 (shared by the instances of one shape) and where
    // to_world puts it. Embree intersects it through callbacks (scene/embree_sdf_grid.cpp); it has no
    // area (Mitsuba's sdfgrid cannot emit) and no uv (0, 0 as in Mitsuba).
    std::shared_ptr<const SdfGrid> sdf_grid;
    Transform sdf_to_world;
    // sdf_to_world's inverse, which every ray against the grid goes through; set by finalize().
    const Transform &sdf_to_object() const { return sdf_to_object_; }
    // Curve data (Mitsuba's linearcurve and bsplinecurve), world space: the control points with their
    // radii, and the first control point of each segment (CurveData::segments). Curves have no area and
    // cannot emit, as in Mitsuba, which cannot sample a point on them.
    CurveBasis curve_basis = CurveBasis::Linear;
    std::vector<CurvePoint> curve_points;
    std::vector<uint32_t> curve_segments;

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
    // The attribute of that name, null when the shape has none. Inline: textures (a library below this
    // one) read it.
    const MeshAttribute *attribute(const std::string &name) const {
        if (attributes)
            for (const MeshAttribute &a : *attributes)
                if (a.name == name) return &a;
        return nullptr;
    }
    size_t triangle_count() const { return indices.size() / 3; }
    float surface_area() const { return area_; }
    BBox bounds() const;

    // Uniform sampling of a point by area.
    // with_uv = false leaves ps.uv unset (a caller with nothing textured to look up skips its fetch).
    PositionSample sample_position(Vec2 u, bool with_uv = true) const;
    float pdf_position() const { return area_ > 0 ? 1.f / area_ : 0.f; }

    // Completes a hit record from Embree's primitive index and barycentrics (a sphere's: unused; a curve's:
    // b1 is the parameter along segment prim).
    void fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                          SurfaceInteraction &si) const;
    // Whether its hits may be filled eight at a time (scene/hit_lanes.h): a mesh whose BSDF needs no
    // tangents, which is most of every scene's hits.
    bool fills_in_lanes() const { return kind == Kind::Mesh && !tangents; }

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

    // Cache prefetch of what fill_interaction(prim) reads: its triangle's record, two cache lines.
    // Inline: it runs once per ray, from the integrator's batch loop.
    void prefetch(uint32_t prim) const {
        if (kind != Kind::Mesh) return;
        const char *record = reinterpret_cast<const char *>(&hit_triangles_[prim]);
        __builtin_prefetch(record);
        __builtin_prefetch(record + sizeof(HitTriangle) - 1);
    }

private:
    friend void add_lane(HitLanes &h, const Shape &shape, uint32_t prim, float b1, float b2, float t, const Vec3 &d,
                         SurfaceInteraction &out);
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
    std::optional<Parallelogram> find_parallelogram() const;
    // fill_interaction of an SDF grid: Mitsuba's normals at the hit, no uv or dp/du.
    void fill_sdf_interaction(const Ray &ray, float t, SurfaceInteraction &si) const;

    float lane_flip_ = 0, lane_vertex_normals_ = 0, lane_has_uv_ = 0;  // HitLanes' masks, set by finalize()
    Transform sdf_to_object_;
    float area_ = 0;
    Distribution1D triangle_distribution_;
    std::vector<SamplingTriangle> sampling_triangles_;  // precomputed for emitters (sampled at every NEE)
    std::vector<HitTriangle> hit_triangles_;            // one per triangle, built by finalize()
    std::optional<Parallelogram> parallelogram_;
};

}  // namespace neepp
