// Mitsuba 3's `projector` light: the perspective camera's reciprocal, a point at the origin of its frame
// projecting an irradiance texture along +z through the camera's pixel-to-direction mapping (fov,
// fov_axis or focal_length, the texture's aspect ratio). The texture is the irradiance on the image
// plane at z = 1, times pi and `scale` (as Mitsuba's): the intensity toward a direction at angle theta to
// the axis is pi scale E(uv) / cos^3 theta, so a constant texture lights a plane facing the projector
// evenly. Emitted rays leave uniformly over the image plane.
#pragma once
#include "neepp/base/light.h"
#include "neepp/base/texture.h"
#include "neepp/scene/camera.h"

namespace neepp {

class ProjectorLight final : public Light {
public:
    // frame: where it is and how it projects (to_world, fov, fov_axis; width and height are the texture's
    // resolution, 1 x 1 for a constant); finalized here.
    ProjectorLight(Camera frame, TexturePtr irradiance, float scale);
    DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const override;
    float pdf_direction(const Vec3 &, const DirectionSample &) const override { return 0.f; }
    EmissionSample sample_emission(Vec2 u_pos, Vec2 u_dir) const override;
    EmissionDensity pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &w) const override;
    Color power() const override;
    bool is_delta() const override { return true; }
    std::optional<LightBounds> bounds() const override;
    // The intensity (W/sr) toward world direction w (unit, leaving the light); zero outside the image.
    Color intensity(const Vec3 &w) const;

private:
    Color irradiance_at(Vec2 uv) const;
    Camera frame_;
    TexturePtr irradiance_;
    float scale_;
    Vec3 position_, axis_;
};

}  // namespace neepp
