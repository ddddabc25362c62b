#include "neepp/shapes/triangle_mesh.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

#include "neepp/math/warp.h"

namespace neepp {

void TriangleMesh::precompute() {
    // Embree shares positions (embree_geometry) and reads a vertex buffer's last vertex with a 16-byte
    // load: one spare element of capacity past the end. Mesh readers allocate it; a copied mesh may not have it.
    if (positions.capacity() == positions.size()) positions.reserve(positions.size() + 1);
    const float all_bits = std::bit_cast<float>(~0u);
    lane_flip_ = flip_normals ? -0.f : 0.f;
    lane_vertex_normals_ = (face_normals || normals.empty()) ? 0.f : all_bits;
    lane_has_uv_ = uvs.empty() ? 0.f : all_bits;
    std::vector<float> areas(triangle_count());
    double total = 0;
    for (size_t i = 0; i < areas.size(); ++i) {
        const Vec3 &p0 = positions[indices[3 * i]], &p1 = positions[indices[3 * i + 1]], &p2 = positions[indices[3 * i + 2]];
        areas[i] = 0.5f * norm(cross(p1 - p0, p2 - p0));
        total += areas[i];
    }
    area_ = float(total);
    triangle_distribution_ = Distribution1D(std::move(areas));
    sampling_triangles_.clear();
    hit_triangles_.resize(triangle_count());
    for (size_t i = 0; i < hit_triangles_.size(); ++i) {
        HitTriangle &t = hit_triangles_[i];
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = indices[3 * i + k];
            t.p[k] = positions[v];
            t.n[k] = normals.empty() ? Vec3() : normals[v];
            t.uv[k] = uvs.empty() ? Vec2() : uvs[v];
        }
    }
    parallelogram_ = find_parallelogram();
    if (area_light)
        for (size_t i = 0; i < triangle_count(); ++i) sampling_triangles_.push_back(sampling_triangle(i));
}

TriangleMesh::SamplingTriangle TriangleMesh::sampling_triangle(size_t tri) const {
    if (tri < sampling_triangles_.size()) return sampling_triangles_[tri];
    const Vec3 &p0 = positions[indices[3 * tri]], &p1 = positions[indices[3 * tri + 1]], &p2 = positions[indices[3 * tri + 2]];
    const Vec3 n = normalize(cross(p1 - p0, p2 - p0));
    return {p0, p1 - p0, p2 - p0, flip_normals ? -n : n};
}

std::optional<TriangleMesh::Parallelogram> TriangleMesh::find_parallelogram() const {
    if (triangle_count() != 2) return std::nullopt;
    // The diagonal is the edge the triangles share; the other vertex of each is a corner beside it.
    const uint32_t *t0 = &indices[0], *t1 = &indices[3];
    auto in_t1 = [&](uint32_t v) { return v == t1[0] || v == t1[1] || v == t1[2]; };
    int own0 = -1, shared = 0;
    for (int k = 0; k < 3; ++k) {
        if (in_t1(t0[k])) ++shared;
        else own0 = k;
    }
    if (shared != 2 || own0 < 0) return std::nullopt;
    uint32_t own1 = t1[0];
    for (int k = 0; k < 3; ++k)
        if (t1[k] != t0[0] && t1[k] != t0[1] && t1[k] != t0[2]) own1 = t1[k];
    // Corners in order around the quad: s (a diagonal end), a, the other diagonal end, b.
    const uint32_t a = t0[own0], s = t0[(own0 + 1) % 3], s2 = t0[(own0 + 2) % 3], b = own1;
    const Vec3 e1 = positions[a] - positions[s], e2 = positions[b] - positions[s];
    // A parallelogram's diagonals bisect each other: s + s2 = a + b.
    const Vec3 gap = positions[s] + positions[s2] - positions[a] - positions[b];
    const float scale = std::max(norm(e1), norm(e2));
    if (!(scale > 0) || norm(gap) > 1e-5f * scale) return std::nullopt;
    const SamplingTriangle f0 = sampling_triangle(0), f1 = sampling_triangle(1);
    if (!(dot(f0.n, f1.n) > 0.9999f)) return std::nullopt;  // wound inconsistently: keep per-triangle normals
    // Vertex normals that bend away from the face vary the shading normal, which decides where the
    // surface emits: sampled per triangle, which interpolates them.
    if (!face_normals)
        for (const Vec3 &vn : normals)
            if (!(dot(flip_normals ? -vn : vn, f0.n) > 0.9999f * norm(vn))) return std::nullopt;
    Parallelogram q;
    q.p0 = positions[s], q.e1 = e1, q.e2 = e2, q.n = f0.n;
    if (!uvs.empty()) {
        q.uv0 = uvs[s], q.duv1 = uvs[a] - uvs[s], q.duv2 = uvs[b] - uvs[s];
        const Vec2 uv_gap = uvs[s] + uvs[s2] - uvs[a] - uvs[b];
        q.uv_affine = std::abs(uv_gap.x) + std::abs(uv_gap.y) <= 1e-6f * (1.f + std::abs(uvs[s].x) + std::abs(uvs[s].y));
    }
    return q;
}

BBox TriangleMesh::bounds() const {
    BBox b;
    for (const Vec3 &p : positions) b.expand(p);
    return b;
}

RTCGeometry TriangleMesh::embree_geometry(RTCDevice device) const {
    if (indices.empty()) return nullptr;  // nothing to intersect; the shape keeps its index all the same
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree reads the mesh's own arrays rather than copies of them: the mesh outlives the Embree scene
    // and does not change once built. The vertex buffer needs readable bytes past its last vertex
    // (precompute() reserves them); without them (a mesh never precomputed), Embree gets a padded copy.
    static_assert(sizeof(Vec3) == 3 * sizeof(float) && sizeof(uint32_t) == 4);
    if (positions.capacity() > positions.size()) {
        rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, positions.data(), 0, sizeof(Vec3),
                                   positions.size());
    } else {
        float *v = (float *)rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(Vec3),
                                                    positions.size());
        std::copy_n(&positions[0].x, 3 * positions.size(), v);
    }
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices.data(), 0,
                               3 * sizeof(uint32_t), triangle_count());
    return geom;
}

void TriangleMesh::transform(const Transform &to_world) {
    for (Vec3 &p : positions) {
        p = to_world.point(p);
        if (!is_finite(p)) throw std::runtime_error("the transformed mesh has non-finite vertices");
    }
    for (Vec3 &n : normals) {
        n = to_world.normal(n);
        const float len = norm(n);
        if (len > 0) n = n / len;
    }
    if (analytic_uv) analytic_uv->to_world = to_world * analytic_uv->to_world;
}

DirectionCone TriangleMesh::normal_bounds() const {
    DirectionCone cone;
    bool first = true;
    auto add = [&](const DirectionCone &c) {
        cone = first ? c : cone_union(cone, c);
        first = false;
    };
    if (!face_normals)
        for (const Vec3 &vn : normals) {
            const float len = norm(vn);
            if (len > 0) add(DirectionCone{(flip_normals ? -vn : vn) / len, 1.f});
            if (cone.is_entire_sphere()) return cone;
        }
    for (size_t t = 0; t < triangle_count(); ++t) {
        const Vec3 &p0 = positions[indices[3 * t]], &p1 = positions[indices[3 * t + 1]], &p2 = positions[indices[3 * t + 2]];
        Vec3 c = cross(p1 - p0, p2 - p0);
        float len = norm(c);
        if (!(len > 0)) continue;  // degenerate: zero area, never sampled
        add(DirectionCone{(flip_normals ? -c : c) / len, 1.f});
        if (cone.is_entire_sphere()) break;
    }
    return cone;
}

void TriangleMesh::digest(GeometryDigest &d) const {
    d.add("mesh", 4);
    const uint64_t np = positions.size(), ni = indices.size();
    d.add(np);
    d.add(ni);
    if (np) d.add(positions.data(), np * sizeof(Vec3));
    if (ni) d.add(indices.data(), ni * sizeof(uint32_t));
}

PositionSample TriangleMesh::sample_position(Vec2 u, bool with_uv) const {
    PositionSample ps;
    ps.pdf = pdf_position();
    if (parallelogram_ && (!with_uv || parallelogram_->uv_affine)) {
        const Parallelogram &q = *parallelogram_;
        ps.p = q.p0 + q.e1 * u.x + q.e2 * u.y;
        ps.n = ps.ns = q.n;
        if (with_uv) ps.uv = q.uv0 + q.duv1 * u.x + q.duv2 * u.y;
        return ps;
    }
    float ux = u.x;
    uint32_t tri = triangle_distribution_.sample_reuse(ux);
    Vec2 b = square_to_uniform_triangle({ux, u.y});
    const SamplingTriangle t = sampling_triangle(tri);
    ps.p = t.p0 + t.e1 * b.x + t.e2 * b.y;
    ps.n = t.n;
    ps.ns = shading_normal(hit_triangles_[tri], 1.f - b.x - b.y, b.x, b.y, t.n);
    // Same uv as a ray hit at this point gets (barycentrics without texture coordinates), so textured
    // emission agrees between light sampling and BSDF sampling.
    if (analytic_uv) {
        const AnalyticUv::Partials q = analytic_uv->at(ps.p);
        ps.ns = flip_normals ? -q.n : q.n;
        ps.uv = q.uv;
        return ps;
    }
    if (!with_uv) return ps;
    if (uvs.empty()) {
        ps.uv = b;
    } else {
        const uint32_t i0 = indices[3 * tri], i1 = indices[3 * tri + 1], i2 = indices[3 * tri + 2];
        ps.uv = uvs[i0] * (1.f - b.x - b.y) + uvs[i1] * b.x + uvs[i2] * b.y;
    }
    return ps;
}

// Always inlined into fill_interaction (both of its paths; GCC otherwise keeps it out of line, and the
// call is costly on a path this hot). Inlined, its arithmetic may fuse differently with the caller's
// (FMA), which moves a few paths onto other random decisions: the same image statistically, not to the bit.
[[gnu::always_inline]] inline Vec3 TriangleMesh::shading_normal(const HitTriangle &tri, float b0, float b1, float b2, const Vec3 &ng) const {
    if (face_normals || normals.empty()) return ng;
    Vec3 ns = tri.n[0] * b0 + tri.n[1] * b1 + tri.n[2] * b2;
    float len2 = squared_norm(ns);
    if (!(len2 > 0)) return ng;
    ns = ns / std::sqrt(len2);
    return flip_normals ? -ns : ns;
}

void TriangleMesh::fill_interaction(uint32_t prim, float b1, float b2, const Ray &, float t,
                                    SurfaceInteraction &si) const {
    si.t = t;
    si.shape = this;
    si.prim_index = prim;
    const HitTriangle &tri = hit_triangles_[prim];
    const Vec3 &p0 = tri.p[0], &p1 = tri.p[1], &p2 = tri.p[2];
    float b0 = 1.f - b1 - b2;
    Vec3 e1 = p1 - p0, e2 = p2 - p0;
    Vec3 ng = normalize(cross(e1, e2));
    if (flip_normals) ng = -ng;
    si.n = ng;
    si.p = p0 * b0 + p1 * b1 + p2 * b2;

    if (analytic_uv) {
        const AnalyticUv::Partials q = analytic_uv->at(si.p);
        si.uv = q.uv, si.dpdu = q.dpdu, si.dpdv = q.dpdv;
        const Vec3 ns = flip_normals ? -q.n : q.n;  // Mitsuba's analytic shapes have no face_normals
        si.sh_frame = tangents ? frame_along(ns, si.dpdu) : Frame(ns);
        return;
    }
    if (!tangents) {
        si.uv = uvs.empty() ? Vec2(b1, b2) : tri.uv[0] * b0 + tri.uv[1] * b1 + tri.uv[2] * b2;
        si.dpdu = si.dpdv = Vec3(0.f);
        si.sh_frame = Frame(shading_normal(tri, b0, b1, b2, ng));
        return;
    }
    if (!uvs.empty()) {
        Vec2 uv0 = tri.uv[0], uv1 = tri.uv[1], uv2 = tri.uv[2];
        si.uv = uv0 * b0 + uv1 * b1 + uv2 * b2;
        Vec2 du1 = uv1 - uv0, du2 = uv2 - uv0;
        float det = du1.x * du2.y - du1.y * du2.x;
        if (std::abs(det) > 1e-12f) {
            float inv = 1.f / det;
            si.dpdu = (e1 * du2.y - e2 * du1.y) * inv;
            si.dpdv = (e2 * du1.x - e1 * du2.x) * inv;
        } else {
            Frame f(ng);
            si.dpdu = f.s; si.dpdv = f.t;
        }
    } else {
        si.uv = Vec2(b1, b2);  // Mitsuba's default uv on meshes without texture coordinates
        si.dpdu = e1; si.dpdv = e2;
    }

    si.sh_frame = frame_along(shading_normal(tri, b0, b1, b2, ng), si.dpdu);
}

}  // namespace neepp
