// Mitsuba 3's `directional` light: a distant source whose light arrives everywhere along one direction
// with `irradiance` (W/m² on a surface facing it). Delta in direction and infinitely far: next event
// estimation traces a shadow ray toward it, nothing else can hit it, and light paths leave it from a disk
// across the scene's bounding sphere, as the other infinite lights' do.
#pragma once
#include "neepp/lights/environment_light.h"

namespace neepp {

class DirectionalLight final : public Light {
public:
    // travel: the direction the light travels in (Mitsuba's `direction`), any length.
    DirectionalLight(const Vec3 &travel, Color irradiance);
    DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const override;
    float pdf_direction(const Vec3 &, const DirectionSample &) const override { return 0.f; }
    EmissionSample sample_emission(Vec2 u_pos, Vec2 u_dir) const override;
    EmissionDensity pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &) const override {
        return {sphere_.disk_pdf(), 0.f};
    }
    Color power() const override { return irradiance_ * (kPi * sphere_.radius * sphere_.radius); }
    bool is_infinite() const override { return true; }
    bool is_delta() const override { return true; }
    void prepare(const BBox &b) override { sphere_ = SceneSphere(b); }

private:
    Vec3 to_light_;  // unit, from the scene toward the light (against its travel)
    Color irradiance_;
    SceneSphere sphere_;
};

}  // namespace neepp
