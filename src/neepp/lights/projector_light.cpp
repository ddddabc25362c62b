#include "neepp/lights/projector_light.h"

#include <cmath>

namespace neepp {

ProjectorLight::ProjectorLight(Camera frame, TexturePtr irradiance, float scale)
    : frame_(std::move(frame)), irradiance_(std::move(irradiance)), scale_(scale) {
    // Mitsuba's projector clips at 1e-4 and has no far plane.
    frame_.near_clip = 1e-4f;
    frame_.far_clip = kInfinity;
    frame_.finalize();
    position_ = frame_.position();
    axis_ = normalize(frame_.to_world.vector(Vec3(0, 0, 1)));
}

Color ProjectorLight::irradiance_at(Vec2 uv) const {
    SurfaceInteraction si;
    si.uv = uv;
    return irradiance_->eval(si) * (kPi * scale_);
}

Color ProjectorLight::intensity(const Vec3 &w) const {
    // The camera's direction density is 1 / (A cos^3): the intensity is E A times it, with A the image's
    // area at distance 1 (so that ∫ I dω over the image is pi scale ∫ E dA).
    const float pdf = frame_.pdf_direction(w);
    if (!(pdf > 0)) return Color(0.f);
    const CameraConnection c = frame_.connect(position_ + w);
    if (!c.valid()) return Color(0.f);
    const Vec2 uv(c.raster.x / float(frame_.width), c.raster.y / float(frame_.height));
    return irradiance_at(uv) * (pdf / frame_.pdf_direction(axis_));
}

DirectionSample ProjectorLight::sample_direction(const Vec3 &ref, Vec2, Color &radiance) const {
    float dist2;
    const DirectionSample ds = direction_sample_to_point(position_, ref, dist2);
    radiance = intensity(-ds.d) / dist2;
    return ds;
}

EmissionSample ProjectorLight::sample_emission(Vec2, Vec2 u_dir) const {
    EmissionSample es;
    es.p = position_;
    const Ray through = frame_.generate_ray(u_dir);
    es.ray = Ray{position_, through.d, 0.f, kInfinity};
    es.radiance = intensity(es.ray.d);
    es.pdf_pos = 1.f;
    es.pdf_dir = frame_.pdf_direction(es.ray.d);
    return es;
}

EmissionDensity ProjectorLight::pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &w) const {
    return {1.f, frame_.pdf_direction(w)};
}

Color ProjectorLight::power() const {
    // pi scale E over the image plane at distance 1, whose area is 1 / the density along the axis.
    return irradiance_->mean() * (kPi * scale_ / frame_.pdf_direction(axis_));
}

std::optional<LightBounds> ProjectorLight::bounds() const {
    LightBounds b;
    b.bounds.expand(position_);
    b.normals = DirectionCone{axis_, 1.f};
    // Its image's corners are the widest it shines (a little wider, for rounding).
    b.cos_theta_e = std::max(dot(frame_.generate_ray(Vec2(0.f, 0.f)).d, axis_) - 1e-3f, -1.f);
    b.phi = luminance(power());
    return b;
}

}  // namespace neepp
