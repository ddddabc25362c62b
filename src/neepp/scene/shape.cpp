#include "neepp/scene/shape.h"

#include "neepp/math/warp.h"

namespace neepp {

void Shape::finalize() {
    if (kind == Kind::Sphere) {
        area_ = 4.f * kPi * radius * radius;
        return;
    }
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
    if (area_light)
        for (size_t i = 0; i < triangle_count(); ++i) sampling_triangles_.push_back(sampling_triangle(i));
}

Shape::SamplingTriangle Shape::sampling_triangle(size_t tri) const {
    if (tri < sampling_triangles_.size()) return sampling_triangles_[tri];
    const Vec3 &p0 = positions[indices[3 * tri]], &p1 = positions[indices[3 * tri + 1]], &p2 = positions[indices[3 * tri + 2]];
    const Vec3 n = normalize(cross(p1 - p0, p2 - p0));
    return {p0, p1 - p0, p2 - p0, flip_normals ? -n : n};
}

BBox Shape::bounds() const {
    BBox b;
    if (kind == Kind::Sphere) {
        b.expand(center - Vec3(radius));
        b.expand(center + Vec3(radius));
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
        ps.n = flip_normals ? -d : d;
        return ps;
    }
    float ux = u.x;
    uint32_t tri = triangle_distribution_.sample_reuse(ux);
    Vec2 b = square_to_uniform_triangle({ux, u.y});
    const SamplingTriangle t = sampling_triangle(tri);
    ps.p = t.p0 + t.e1 * b.x + t.e2 * b.y;
    ps.n = t.n;
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

void Shape::prefetch(uint32_t prim, int level) const {
    if (kind == Kind::Sphere) return;
    if (level == 0) {
        __builtin_prefetch(&indices[3 * prim]);
        return;
    }
    for (int k = 0; k < 3; ++k) {
        const uint32_t i = indices[3 * prim + k];
        __builtin_prefetch(&positions[i]);
        if (!normals.empty()) __builtin_prefetch(&normals[i]);
        if (!uvs.empty()) __builtin_prefetch(&uvs[i]);
    }
}

void Shape::fill_interaction(uint32_t prim, float b1, float b2, const Ray &ray, float t,
                             SurfaceInteraction &si) const {
    si.t = t;
    si.p = ray.at(t);
    si.shape = this;
    si.prim_index = prim;
    if (kind == Kind::Sphere) {
        Vec3 local = normalize(si.p - center);
        si.p = center + local * radius;  // re-project for precision
        si.n = flip_normals ? -local : local;
        // Mitsuba's sphere uv: (phi / 2pi, theta / pi) in the sphere's frame.
        float phi = std::atan2(local.y, local.x);
        if (phi < 0) phi += 2.f * kPi;
        si.uv = Vec2(phi * kInv2Pi, std::acos(std::clamp(local.z, -1.f, 1.f)) * kInvPi);
        si.dpdu = Vec3(-local.y, local.x, 0) * (2.f * kPi * radius);
        si.dpdv = cross(si.n, si.dpdu);
        si.sh_frame = Frame(si.n);
        return;
    }
    uint32_t i0 = indices[3 * prim], i1 = indices[3 * prim + 1], i2 = indices[3 * prim + 2];
    const Vec3 &p0 = positions[i0], &p1 = positions[i1], &p2 = positions[i2];
    float b0 = 1.f - b1 - b2;
    Vec3 e1 = p1 - p0, e2 = p2 - p0;
    Vec3 ng = normalize(cross(e1, e2));
    if (flip_normals) ng = -ng;
    si.n = ng;
    si.p = p0 * b0 + p1 * b1 + p2 * b2;

    if (!uvs.empty()) {
        Vec2 uv0 = uvs[i0], uv1 = uvs[i1], uv2 = uvs[i2];
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

    Vec3 ns = ng;
    if (!face_normals && !normals.empty()) {
        ns = normals[i0] * b0 + normals[i1] * b1 + normals[i2] * b2;
        float len2 = squared_norm(ns);
        ns = len2 > 0 ? ns / std::sqrt(len2) : ng;
        if (flip_normals) ns = -ns;
    }
    // Shading frame aligned with dp/du (Gram-Schmidt), as Mitsuba does, so anisotropic and bump-mapped
    // materials have a consistent tangent.
    Vec3 s = si.dpdu - ns * dot(ns, si.dpdu);
    float s2 = squared_norm(s);
    if (s2 > 1e-20f && std::isfinite(s2)) {
        s = s / std::sqrt(s2);
        si.sh_frame = Frame(s, cross(ns, s), ns);
    } else {
        si.sh_frame = Frame(ns);
    }
}

}  // namespace neepp
