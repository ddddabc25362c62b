// Mitsuba 3's `spot` light: a point light at the origin of its to_world frame shining along +z with a
// linear falloff: full `intensity` (W/sr) within beam_width of the axis, ramping down to zero at
// cutoff_angle (angles in degrees; beam_width defaults to 3/4 of cutoff_angle, as Mitsuba's does).
// An optional `texture` is projected over the cone, multiplying the intensity: the direction with local
// (x, y, z) looks up uv = 0.5 + 0.5 (x, y) / (z tan cutoff_angle), so the texture's square spans the
// cutoff cone's tangent plane at z = 1. Emitted rays still fill the cone uniformly, as Mitsuba's do.
#pragma once
#include "neepp/base/light.h"
#include "neepp/base/texture.h"
#include "neepp/math/transform.h"

namespace neepp {

class SpotLight final : public Light {
public:
    // texture: null for none; when set, it must vary over uv (Mitsuba refuses a constant one).
    SpotLight(const Transform &to_world, Color intensity, float cutoff_angle_deg, float beam_width_deg,
              TexturePtr texture = nullptr);
    DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const override;
    float pdf_direction(const Vec3 &, const DirectionSample &) const override { return 0.f; }
    EmissionSample sample_emission(Vec2 u_pos, Vec2 u_dir) const override;
    EmissionDensity pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &w) const override;
    Color power() const override { return power_; }
    bool is_delta() const override { return true; }
    std::optional<LightBounds> bounds() const override;
    // The falloff factor in [0, 1] for a direction leaving the light (world space, unit length).
    float falloff(const Vec3 &w) const;
    // The intensity (W/sr) toward world direction w (unit, leaving the light): intensity × falloff ×
    // the projected texture.
    Color intensity(const Vec3 &w) const;

private:
    Vec3 position_, axis_;
    Transform to_world_;
    Color intensity_;
    TexturePtr texture_;
    float cutoff_rad_, cos_cutoff_, cos_beam_, inv_transition_, uv_factor_;
    Color power_;  // ∫ intensity(ω) dω
};

}  // namespace neepp
