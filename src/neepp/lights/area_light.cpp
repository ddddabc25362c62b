#include "neepp/lights/area_light.h"

#include "neepp/math/warp.h"
#include "neepp/shapes/triangle_mesh.h"

namespace neepp {

DirectionSample AreaLight::sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const {
    PositionSample ps = shape_->sample_position(u, !constant_);
    DirectionSample ds;
    ds.p = ps.p;
    ds.n = ps.n;
    ds.ns = ps.ns;
    Vec3 d = ps.p - ref;
    float dist2 = squared_norm(d);
    ds.dist = std::sqrt(dist2);
    ds.d = d / ds.dist;
    radiance = Color(0.f);
    if (!emits_toward(ds) || !(dist2 > 0)) return ds;
    ds.pdf = ps.pdf * dist2 / std::abs(dot(ds.n, ds.d));
    if (constant_) {
        radiance = constant_radiance_;
        return ds;
    }
    SurfaceInteraction si;
    si.p = ps.p; si.n = ps.n; si.uv = ps.uv;
    radiance = radiance_->eval(si);
    return ds;
}

void AreaLight::prepare(const BBox &) {
    lane_record_ = nullptr;
    // A parallelogram's sample needs no triangle choice, and with constant radiance no uv: the lane
    // kernel's case. Its shading normal is its face's (TriangleMesh::find_parallelogram checks vertex normals).
    const auto *mesh = dynamic_cast<const TriangleMesh *>(shape_);
    if (!LightSampleLanes::kEnabled || !constant_ || !mesh || !mesh->parallelogram()) return;
    const TriangleMesh::Parallelogram *q = &*mesh->parallelogram();
    lane_.p0 = q->p0, lane_.e1 = q->e1, lane_.e2 = q->e2, lane_.n = q->n;
    lane_.pdf = shape_->pdf_position();
    lane_.radiance = constant_radiance_;
    lane_record_ = &lane_;
}

float AreaLight::pdf_direction(const Vec3 &ref, const DirectionSample &ds) const {
    if (!emits_toward(ds)) return 0.f;
    return shape_->pdf_position() * ds.dist * ds.dist / std::abs(dot(ds.n, ds.d));
}

EmissionSample AreaLight::sample_emission(Vec2 u_pos, Vec2 u_dir) const {
    const PositionSample ps = shape_->sample_position(u_pos, !constant_);
    EmissionSample es;
    es.p = ps.p;
    es.n = ps.n;
    es.ns = ps.ns;
    es.uv = ps.uv;
    const Frame frame(ps.ns);
    const Vec3 local = square_to_cosine_hemisphere(u_dir);
    const Vec3 d = frame.to_world(local);
    es.ray = spawn_ray(ps.p, ps.n, d);
    es.pdf_pos = ps.pdf;
    es.pdf_dir = square_to_cosine_hemisphere_pdf(local);
    if (!(es.pdf_dir > 0) || dot(ps.n, d) == 0.f) return es;
    if (constant_) {
        es.radiance = constant_radiance_;
    } else {
        SurfaceInteraction si;
        si.p = ps.p; si.n = ps.n; si.uv = ps.uv;
        es.radiance = radiance_->eval(si);
    }
    return es;
}

EmissionDensity AreaLight::pdf_emission(const Vec3 &, const Vec3 &n, const Vec3 &ns, const Vec3 &w) const {
    const float cos_s = dot(ns, w);
    if (!(cos_s > 0) || dot(n, w) == 0.f) return {};
    return {shape_->pdf_position(), cos_s * kInvPi};
}

Color AreaLight::eval_surface(const SurfaceInteraction &si, const Vec3 &w) const {
    return dot(si.sh_frame.n, w) > 0 ? radiance_->eval(si) : Color(0.f);
}

std::optional<LightBounds> AreaLight::bounds() const {
    LightBounds b;
    b.bounds = shape_->bounds();
    b.phi = luminance(power());
    b.cos_theta_e = 0.f;  // cosine emission: nothing beyond 90 degrees from the normal
    b.normals = shape_->normal_bounds();
    return b;
}

}  // namespace neepp
