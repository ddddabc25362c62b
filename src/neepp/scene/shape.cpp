#include "neepp/scene/shape.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "neepp/math/warp.h"
#include "neepp/scene/sdf_grid.h"

namespace neepp {

void Shape::finalize() {
    tangents = !bsdf || bsdf->needs_tangents();
    bsdf_flags = bsdf ? bsdf->flags() : 0;
    const float all_bits = std::bit_cast<float>(~0u);
    lane_flip_ = flip_normals ? -0.f : 0.f;
    lane_vertex_normals_ = (face_normals || normals.empty()) ? 0.f : all_bits;
    lane_has_uv_ = uvs.empty() ? 0.f : all_bits;
    if (kind == Kind::Sphere) {
        area_ = 4.f * kPi * radius * radius;
        return;
    }
    if (kind == Kind::SdfGrid) {
        area_ = 0;  // as Mitsuba's: nothing samples a point on it
        sdf_to_object_ = sdf_to_world.inverse();
        return;
    }
    if (kind == Kind::Curve) return;  // no area: curves cannot emit
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

Shape::SamplingTriangle Shape::sampling_triangle(size_t tri) const {
    if (tri < sampling_triangles_.size()) return sampling_triangles_[tri];
    const Vec3 &p0 = positions[indices[3 * tri]], &p1 = positions[indices[3 * tri + 1]], &p2 = positions[indices[3 * tri + 2]];
    const Vec3 n = normalize(cross(p1 - p0, p2 - p0));
    return {p0, p1 - p0, p2 - p0, flip_normals ? -n : n};
}

std::optional<Shape::Parallelogram> Shape::find_parallelogram() const {
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

BBox Shape::bounds() const {
    BBox b;
    if (kind == Kind::Sphere) {
        b.expand(center - Vec3(radius));
        b.expand(center + Vec3(radius));
    } else if (kind == Kind::SdfGrid) {
        for (int k = 0; k < 8; ++k) b.expand(sdf_to_world.point(Vec3(float(k & 1), float(k >> 1 & 1), float(k >> 2 & 1))));
    } else if (kind == Kind::Curve) {
        // A segment's every point is a convex combination of its control points, each moved by its own radius.
        for (const CurvePoint &cp : curve_points) {
            b.expand(cp.p - Vec3(cp.radius));
            b.expand(cp.p + Vec3(cp.radius));
        }
    } else {
        for (const Vec3 &p : positions) b.expand(p);
    }
    return b;
}

PositionSample Shape::sample_position(Vec2 u, bool with_uv) const {
    PositionSample ps;
    ps.pdf = pdf_position();
    if (kind == Kind::Sphere) {
        Vec3 d = square_to_uniform_sphere(u);
        ps.p = center + d * radius;
        ps.n = ps.ns = flip_normals ? -d : d;
        return ps;
    }
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
    if (!with_uv) return ps;
    if (uvs.empty()) {
        ps.uv = b;
    } else {
        const uint32_t i0 = indices[3 * tri], i1 = indices[3 * tri + 1], i2 = indices[3 * tri + 2];
        ps.uv = uvs[i0] * (1.f - b.x - b.y) + uvs[i1] * b.x + uvs[i2] * b.y;
    }
    return ps;
}

namespace {

// The shading frame around n with s along dp/du made perpendicular to n (Gram-Schmidt), as Mitsuba aligns
// it, so anisotropic and bump-mapped materials have a consistent tangent; around n alone where dp/du has
// no part across n.
[[gnu::always_inline]] inline Frame frame_along(const Vec3 &n, const Vec3 &dpdu) {
    Vec3 s = dpdu - n * dot(n, dpdu);
    const float s2 = squared_norm(s);
    if (!(s2 > 1e-20f && std::isfinite(s2))) return Frame(n);
    s = s / std::sqrt(s2);
    return Frame(s, cross(n, s), n);
}

}  // namespace

// Always inlined into fill_interaction (both of its paths; GCC otherwise keeps it out of line, and the
// call is costly on a path this hot). Inlined, its arithmetic may fuse differently with the caller's
// (FMA), which moves a few paths onto other random decisions: the same image statistically, not to the bit.
[[gnu::always_inline]] inline Vec3 Shape::shading_normal(const HitTriangle &tri, float b0, float b1, float b2, const Vec3 &ng) const {
    if (face_normals || normals.empty()) return ng;
    Vec3 ns = tri.n[0] * b0 + tri.n[1] * b1 + tri.n[2] * b2;
    float len2 = squared_norm(ns);
    if (!(len2 > 0)) return ng;
    ns = ns / std::sqrt(len2);
    return flip_normals ? -ns : ns;
}

void Shape::fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                             SurfaceInteraction &si) const {
    si.t = t;
    si.shape = this;
    si.prim_index = prim;
    if (kind == Kind::Sphere) {
        si.p = ray.at(t);
        const Vec3 d = normalize(si.p - center);
        si.p = center + d * radius;  // re-project for precision
        si.n = flip_normals ? -d : d;
        // Mitsuba's sphere uv: (phi / 2pi, theta / pi) in the sphere's frame.
        const Vec3 local(dot(d, sphere_axes[0]), dot(d, sphere_axes[1]), dot(d, sphere_axes[2]));
        float phi = std::atan2(local.y, local.x);
        if (phi < 0) phi += 2.f * kPi;
        si.uv = Vec2(phi * kInv2Pi, std::acos(std::clamp(local.z, -1.f, 1.f)) * kInvPi);
        si.dpdu = (sphere_axes[1] * local.x - sphere_axes[0] * local.y) * (2.f * kPi * radius);
        si.dpdv = cross(si.n, si.dpdu);
        // Aligned with dp/du where the BSDF reads tangents, as Mitsuba; at the poles dp/du vanishes.
        const float du2 = squared_norm(si.dpdu);
        if (tangents && du2 > 0.f) {
            const Vec3 s = si.dpdu / std::sqrt(du2);
            si.sh_frame = Frame(s, cross(si.n, s), si.n);
        } else {
            si.sh_frame = Frame(si.n);
        }
        return;
    }
    if (kind == Kind::SdfGrid) return fill_sdf_interaction(ray, t, si);
    if (kind == Kind::Curve) {
        si.p = ray.at(t);
        const CurveHit h = curve_hit(curve_basis, &curve_points[curve_segments[prim]], prim,
                                     uint32_t(curve_segments.size()), b1, si.p);
        si.n = h.n;
        si.uv = h.uv;
        // Mitsuba's curves shade with the geometric normal, the frame's s around the tube.
        if (tangents) {
            si.dpdu = h.dpdu, si.dpdv = h.dpdv;
            si.sh_frame = frame_along(h.n, h.dpdu);
        } else {
            si.dpdu = si.dpdv = Vec3(0.f);
            si.sh_frame = Frame(h.n);
        }
        return;
    }
    const HitTriangle &tri = hit_triangles_[prim];
    const Vec3 &p0 = tri.p[0], &p1 = tri.p[1], &p2 = tri.p[2];
    float b0 = 1.f - b1 - b2;
    Vec3 e1 = p1 - p0, e2 = p2 - p0;
    Vec3 ng = normalize(cross(e1, e2));
    if (flip_normals) ng = -ng;
    si.n = ng;
    si.p = p0 * b0 + p1 * b1 + p2 * b2;

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

// As Mitsuba's sdfgrid: the point on the ray; the geometric normal the gradient of the hit voxel's
// interpolant, the shading normal by the grid's `normals` option, both moved by to_world as normals are.
void Shape::fill_sdf_interaction(const Ray &ray, float t, SurfaceInteraction &si) const {
    si.p = ray.at(t);
    const Vec3 local = sdf_to_object_.point(si.p);
    // A gradient of zero (a flat spot of a degenerate grid) has no direction: the side the ray came from.
    auto world_normal = [&](const Vec3 &n, const Vec3 &fallback) {
        const Vec3 w = sdf_to_world.normal(n);
        const float len = norm(w);
        return len > 0 && std::isfinite(len) ? w / len : fallback;
    };
    si.n = world_normal(sdf_grid->gradient(local), -normalize(ray.d));
    si.sh_frame = Frame(world_normal(sdf_grid->shading_normal(local), si.n));
    si.uv = Vec2(0.f, 0.f);
    si.dpdu = si.dpdv = Vec3(0.f);
}

}  // namespace neepp
