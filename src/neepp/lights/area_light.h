// Mitsuba's `area` emitter: uniform radiance from the front side of a shape. As in Mitsuba, the front is
// the side its shading normal faces: on a mesh with vertex normals, a point near the silhouette whose
// interpolated normal has turned away from the viewer does not emit toward it, though its face does.
#pragma once
#include "neepp/base/light.h"
#include "neepp/base/texture.h"
#include "neepp/lights/light_lanes.h"
#include "neepp/base/shape.h"

namespace neepp {

class AreaLight final : public Light {
public:
    AreaLight(const Shape *shape, TexturePtr radiance)
        : shape_(shape), radiance_(std::move(radiance)), constant_(radiance_->is_constant()),
          constant_radiance_(radiance_->mean()) {}
    // Not copyable: lane_record() points into the light itself.
    AreaLight(const AreaLight &) = delete;
    AreaLight &operator=(const AreaLight &) = delete;
    DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const override;
    float pdf_direction(const Vec3 &ref, const DirectionSample &ds) const override;
    Color eval_surface(const SurfaceInteraction &si, const Vec3 &w) const override;
    // A point by area, a direction cosine-distributed about its shading normal (the side that emits).
    EmissionSample sample_emission(Vec2 u_pos, Vec2 u_dir) const override;
    EmissionDensity pdf_emission(const Vec3 &p, const Vec3 &n, const Vec3 &ns, const Vec3 &w) const override;
    Color power() const override { return radiance_->mean() * (kPi * shape_->surface_area()); }
    // The shape's box, its normal bounds, one-sided cosine emission.
    std::optional<LightBounds> bounds() const override;
    const Shape *shape() const { return shape_; }
    // The radiance its front emits at a point of the shape (its uv and normal as a ray hit there fills
    // them): what other samplers of its points (light_selection/solid_angle_sampling.h) carry.
    bool uniform() const { return constant_; }
    Color radiance_at(const SurfaceInteraction &si) const { return constant_ ? constant_radiance_ : radiance_->eval(si); }
    // A parallelogram of constant radiance is sampled in lanes too (lane_record()).
    void prepare(const BBox &scene_bounds) override;

private:
    // Whether the point of ds emits toward the reference point: it is on the front of its shading
    // normal, and the direction does not graze its surface (the area-to-solid-angle density, which takes
    // the geometric normal, would be infinite).
    static bool emits_toward(const DirectionSample &ds) { return dot(ds.ns, ds.d) < 0.f && dot(ds.n, ds.d) != 0.f; }

    const Shape *shape_;
    TexturePtr radiance_;
    // Most emitters are uniform: a light sample then needs neither the point's uv nor a texture lookup.
    bool constant_;
    Color constant_radiance_;
    LightLaneRecord lane_;
};

}  // namespace neepp
