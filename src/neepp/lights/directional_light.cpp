#include "neepp/lights/directional_light.h"

#include <stdexcept>

namespace neepp {

DirectionalLight::DirectionalLight(const Vec3 &travel, Color irradiance) : irradiance_(irradiance) {
    const float len = norm(travel);
    if (!(len > 0) || !std::isfinite(len)) throw std::invalid_argument("the direction must be a non-zero finite vector");
    to_light_ = -travel / len;
}

DirectionSample DirectionalLight::sample_direction(const Vec3 &ref, Vec2, Color &radiance) const {
    DirectionSample ds;
    ds.d = to_light_;
    ds.dist = kInfinity;
    ds.p = ref + ds.d * (4.f * sphere_.radius);
    ds.pdf = 1.f;
    ds.delta = true;
    radiance = irradiance_;  // the delta's weight: E arrives along ds.d
    return ds;
}

EmissionSample DirectionalLight::sample_emission(Vec2 u_pos, Vec2) const {
    EmissionSample es;
    es.ray = sphere_.disk_ray(to_light_, u_pos);
    es.p = es.ray.o;
    es.radiance = irradiance_;
    es.pdf_pos = sphere_.disk_pdf();
    es.pdf_dir = 1.f;
    return es;
}

}  // namespace neepp
