// Mitsuba's `area` emitter: uniform radiance from the front side of a shape (the side its normal faces).
#pragma once
#include "neepp/lights/light.h"
#include "neepp/materials/texture.h"
#include "neepp/scene/shape.h"

namespace neepp {

class AreaLight final : public Light {
public:
    AreaLight(const Shape *shape, TexturePtr radiance)
        : shape_(shape), radiance_(std::move(radiance)), constant_(radiance_->is_constant()),
          constant_radiance_(radiance_->mean()) {}
    DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const override;
    float pdf_direction(const Vec3 &ref, const DirectionSample &ds) const override;
    Color eval_surface(const SurfaceInteraction &si, const Vec3 &w) const override;
    Color power() const override { return radiance_->mean() * (kPi * shape_->surface_area()); }
    // The shape's box, a cone around its face normals, one-sided cosine emission.
    std::optional<LightBounds> bounds() const override;
    const Shape *shape() const { return shape_; }

private:
    const Shape *shape_;
    TexturePtr radiance_;
    // Most emitters are uniform: a light sample then needs neither the point's uv nor a texture lookup.
    bool constant_;
    Color constant_radiance_;
};

}  // namespace neepp
