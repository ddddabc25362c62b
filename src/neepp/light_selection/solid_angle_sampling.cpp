#include "neepp/light_selection/solid_angle_sampling.h"

#include <algorithm>
#include <cmath>

#include "neepp/math/frame.h"
#include "neepp/math/spherical_rectangle.h"
#include "neepp/math/trig.h"
#include "neepp/shapes/sphere.h"
#include "neepp/shapes/triangle_mesh.h"

namespace neepp {

std::unique_ptr<ContextLightSampler> make_solid_angle_sampler(const Light &light) {
    const auto *area = dynamic_cast<const AreaLight *>(&light);
    if (!area) return nullptr;
    if (const auto *mesh = dynamic_cast<const TriangleMesh *>(area->shape())) {
        const auto &q = mesh->parallelogram();
        if (!q) return nullptr;
        const float l1 = norm(q->e1), l2 = norm(q->e2);
        // A sheared rectangle is a parallelogram the spherical rectangle does not describe. The tolerance
        // is what float round-off leaves of a rotated, scaled square; the density's error it allows is of
        // the same order.
        if (!(l1 > 0 && l2 > 0) || std::abs(dot(q->e1, q->e2)) > 1e-5f * l1 * l2) return nullptr;
        // A textured light needs the uv of the point drawn: affine in the rectangle's coordinates, or,
        // interpolated per triangle, not worth finding here.
        if (!area->uniform() && !q->uv_affine) return nullptr;
        return std::make_unique<RectangleSolidAngleSampler>(*area, q->p0, q->e1, q->e2, q->n, q->uv0, q->duv1, q->duv2);
    }
    if (const auto *sphere = dynamic_cast<const Sphere *>(area->shape())) {
        // Flipped, a sphere emits inward: from outside, its near side is dark and its far side hidden.
        if (sphere->flip_normals) return nullptr;
        return std::make_unique<SphereSolidAngleSampler>(*area, sphere->center, sphere->radius);
    }
    return nullptr;
}

// ---- Rectangles -----------------------------------------------------------------------------------

RectangleSolidAngleSampler::RectangleSolidAngleSampler(const AreaLight &light, const Vec3 &corner, const Vec3 &e1,
                                                       const Vec3 &e2, const Vec3 &n, Vec2 uv0, Vec2 duv1, Vec2 duv2)
    : light_(light), corner_(corner), n_(n), len_x_(norm(e1)), len_y_(norm(e2)), uv0_(uv0), duv1_(duv1), duv2_(duv2) {
    ex_ = e1 / len_x_;
    ey_ = e2 / len_y_;
    center_ = corner + (e1 + e2) * 0.5f;
    near2_ = kNearDiagonals * kNearDiagonals * (len_x_ * len_x_ + len_y_ * len_y_);
}

DirectionSample RectangleSolidAngleSampler::finish(const LightSampleContext &ctx, const LightSampleStart &start,
                                                   Color &radiance) const {
    const Vec3 &ref = ctx.p;
    radiance = Color(0.f);
    // Behind the light, or in its plane: it sends nothing this way, whichever way its points are drawn.
    if (!(dot(ref - corner_, n_) > 0.f)) return {};
    if (!near(ref)) return light_.sample_direction(ref, start.u, radiance);
    const SphericalRectangle rect(ref, corner_, ex_, ey_, len_x_, len_y_);
    const double solid_angle = rect.solid_angle();
    if (solid_angle < kMinSolidAngle) return light_.sample_direction(ref, start.u, radiance);
    float s, t;
    DirectionSample ds;
    ds.p = rect.sample(start.u, s, t);
    ds.n = ds.ns = n_;
    const Vec3 d = ds.p - ref;
    const float dist2 = squared_norm(d);
    ds.dist = std::sqrt(dist2);
    ds.d = d / ds.dist;
    // Seen edge-on after rounding: the direction pdf() could not tell from a hit on the light's back.
    if (!(dist2 > 0) || !(dot(n_, ds.d) < 0.f)) return ds;
    ds.pdf = float(1.0 / solid_angle);
    SurfaceInteraction si;
    if (!light_.uniform()) si.p = ds.p, si.n = n_, si.uv = uv0_ + duv1_ * s + duv2_ * t;
    radiance = light_.radiance_at(si);
    return ds;
}

float RectangleSolidAngleSampler::pdf(const LightSampleContext &ctx, const DirectionSample &ds) const {
    const Vec3 &ref = ctx.p;
    if (!(dot(n_, ds.d) < 0.f) || !(dot(ref - corner_, n_) > 0.f)) return 0.f;
    if (!near(ref)) return light_.pdf_direction(ref, ds);
    const SphericalRectangle rect(ref, corner_, ex_, ey_, len_x_, len_y_);
    const double solid_angle = rect.solid_angle();
    if (solid_angle < kMinSolidAngle) return light_.pdf_direction(ref, ds);
    return float(1.0 / solid_angle);
}

// ---- Spheres --------------------------------------------------------------------------------------

SphereSolidAngleSampler::SphereSolidAngleSampler(const AreaLight &light, const Vec3 &center, float radius)
    : light_(light), center_(center), radius_(radius) {}

bool SphereSolidAngleSampler::sees_cone(const Vec3 &ref, float &one_minus_cos) const {
    const float dist2 = squared_norm(center_ - ref), r2 = radius_ * radius_;
    // On the sphere (within round-off) the cone would be a hemisphere whose edge grazes the surface.
    if (!(dist2 > r2 * 1.0001f)) return false;
    const float sin2_max = r2 / dist2, cos_max = std::sqrt(1.f - sin2_max);
    one_minus_cos = sin2_max / (1.f + cos_max);  // 1 - cos without the cancellation, for distant spheres
    return true;
}

DirectionSample SphereSolidAngleSampler::finish(const LightSampleContext &ctx, const LightSampleStart &start,
                                                Color &radiance) const {
    const Vec3 &ref = ctx.p;
    float one_minus_cos;
    if (!sees_cone(ref, one_minus_cos)) return light_.sample_direction(ref, start.u, radiance);
    radiance = Color(0.f);
    const Vec3 to_center = center_ - ref;
    const float dist_c = norm(to_center);
    const Frame frame(to_center / dist_c);
    // The direction's angle theta from the axis: 1 - cos theta uniform in [0, 1 - cos theta_max], and
    // sin² theta from it without cancellation.
    const float t = start.u.y * one_minus_cos, cos_theta = 1.f - t, sin2_theta = t * (2.f - t);
    // Where it meets the sphere first: the angle alpha at the center between the point and the axis
    // toward ref, from the triangle (ref, center, point): sin theta_max = r / dist_c.
    const float sin_max = radius_ / dist_c;
    const float ratio = std::min(1.f, sin2_theta / (sin_max * sin_max));
    const float cos_alpha = std::clamp(sin2_theta / sin_max + cos_theta * std::sqrt(1.f - ratio), -1.f, 1.f);
    const float sin_alpha = std::sqrt(std::max(0.f, 1.f - cos_alpha * cos_alpha));
    const SinCos phi = sincos_turns(start.u.x);
    const Vec3 n = frame.n * -cos_alpha + (frame.s * phi.cos + frame.t * phi.sin) * sin_alpha;
    DirectionSample ds;
    ds.p = center_ + n * radius_;
    ds.n = ds.ns = n;
    const Vec3 d = ds.p - ref;
    ds.dist = norm(d);
    ds.d = d / ds.dist;
    if (!(dot(n, ds.d) < 0.f)) return ds;  // the silhouette, after rounding: as pdf() sees it
    ds.pdf = 1.f / (2.f * kPi * one_minus_cos);
    SurfaceInteraction si;
    if (!light_.uniform()) light_.shape()->fill_interaction(0, 0.f, 0.f, Ray{ref, ds.d}, ds.dist, si);
    radiance = light_.radiance_at(si);
    return ds;
}

float SphereSolidAngleSampler::pdf(const LightSampleContext &ctx, const DirectionSample &ds) const {
    const Vec3 &ref = ctx.p;
    float one_minus_cos;
    if (!sees_cone(ref, one_minus_cos)) return light_.pdf_direction(ref, ds);
    if (!(dot(ds.n, ds.d) < 0.f)) return 0.f;
    return 1.f / (2.f * kPi * one_minus_cos);
}

}  // namespace neepp
