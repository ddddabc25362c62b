// Points of an area light drawn uniformly in the solid angle the light subtends at the shading point,
// rather than uniformly in its area (the light's own Light::sample_direction): for rectangles, by the
// spherical rectangle (math/spherical_rectangle.h), for spheres, uniformly in the cone of directions that
// meets them. As pbrt-v4 and Cycles sample these lights; Mitsuba 3 samples them by area.
//
// Why: by area, a sample's weight carries cos(light) / distance², which varies across a large light seen
// from nearby (a ceiling panel over a bathroom's walls, a light through a door ajar) and makes the noise
// of its direct light; in solid angle, the weight is constant over the light, and what is left is the
// BSDF's cosine and the radiance.
//
// Where a light is not one of these, or the point is where the parametrization fails (a rectangle of tiny
// solid angle; a point inside a sphere), the light samples itself by area, and the density reported is
// that sampling's: which of the two draws is decided by the shading point alone, so the density of a
// point found by a BSDF-sampled ray is exactly the density with which it would have been drawn.
#pragma once
#include <memory>

#include "neepp/light_selection/within_light_sampling.h"
#include "neepp/lights/area_light.h"

namespace neepp {

// The solid-angle sampler of `light`, or null where it samples itself by area: not an area light, or its
// shape is neither a rectangle (a parallelogram with orthogonal edges, whose uv, if its radiance is
// textured, is affine across it) nor a sphere that emits outward.
std::unique_ptr<ContextLightSampler> make_solid_angle_sampler(const Light &light);

// A rectangle light: points of the spherical rectangle where the shading point is near it (within
// kNearDiagonals of its diagonal from its center) and it subtends at least kMinSolidAngle; by area
// farther away; nothing where the shading point is behind it (it emits from its front only).
class RectangleSolidAngleSampler final : public ContextLightSampler {
public:
    // Farther than this many diagonals from its center, the light samples itself: there cos / distance²
    // varies less across it, and a spherical rectangle (two atan2, a cos and a sin in double, square
    // roots) costs more time than the variance it saves (the measurements that chose it are in
    // docs/neepp.md, "Solid-angle sampling of area lights").
    static constexpr float kNearDiagonals = 0.5f;
    // Below this solid angle (sr), the light's own sampling: the spherical rectangle's inversion loses
    // precision as the solid angle shrinks, and the cosine and distance, nearly constant across a light
    // this small, leave little for it to gain.
    static constexpr double kMinSolidAngle = 1e-5;

    RectangleSolidAngleSampler(const AreaLight &light, const Vec3 &corner, const Vec3 &e1, const Vec3 &e2,
                               const Vec3 &n, Vec2 uv0, Vec2 duv1, Vec2 duv2);
    DirectionSample finish(const LightSampleContext &ctx, const LightSampleStart &start, Color &radiance) const override;
    float pdf(const LightSampleContext &ctx, const DirectionSample &ds) const override;
    // Far from the light (and in front of it), its own sampling, in lanes where it has them.
    const LightLaneRecord *own_lane_record(const LightSampleContext &ctx) const override {
        return dot(ctx.p - corner_, n_) > 0.f && !near(ctx.p) ? light_.lane_record() : nullptr;
    }

private:
    // Whether the spherical rectangle draws the points seen from ref (else the light's own sampling).
    bool near(const Vec3 &ref) const { return squared_norm(ref - center_) <= near2_; }

    const AreaLight &light_;
    Vec3 corner_, ex_, ey_, n_;  // ex, ey unit along the edges; n the side that emits
    Vec3 center_;
    float near2_;
    float len_x_, len_y_;
    Vec2 uv0_, duv1_, duv2_;  // uv = uv0 + s duv1 + t duv2 at corner + s e1 + t e2
};

// A sphere light seen from outside: a direction uniform in the cone of its silhouette, and the nearer point
// of the sphere along it. From inside (or on) the sphere, its own sampling.
class SphereSolidAngleSampler final : public ContextLightSampler {
public:
    SphereSolidAngleSampler(const AreaLight &light, const Vec3 &center, float radius);
    DirectionSample finish(const LightSampleContext &ctx, const LightSampleStart &start, Color &radiance) const override;
    float pdf(const LightSampleContext &ctx, const DirectionSample &ds) const override;

private:
    // Whether ref sees the sphere as a cone (it is outside it, by a margin that keeps the cone's edge
    // well-defined), and then 1 - cos of the cone's half-angle.
    bool sees_cone(const Vec3 &ref, float &one_minus_cos) const;

    const AreaLight &light_;
    Vec3 center_;
    float radius_;
};

}  // namespace neepp
