#include "neepp/lights/spot_light.h"

#include <cmath>
#include <stdexcept>
#include "neepp/math/warp.h"

namespace neepp {

SpotLight::SpotLight(const Transform &to_world, Color intensity, float cutoff_angle_deg, float beam_width_deg)
    : to_world_(to_world), intensity_(intensity) {
    if (!(cutoff_angle_deg > 0 && cutoff_angle_deg <= 180))
        throw std::invalid_argument("cutoff_angle must be in (0, 180] degrees");
    if (!(beam_width_deg >= 0 && beam_width_deg < cutoff_angle_deg))
        throw std::invalid_argument("beam_width must be in [0, cutoff_angle)");
    position_ = to_world.point(Vec3(0.f));
    axis_ = normalize(to_world.vector(Vec3(0, 0, 1)));
    cutoff_rad_ = cutoff_angle_deg * kPi / 180.f;
    const float beam_rad = beam_width_deg * kPi / 180.f;
    inv_transition_ = 1.f / (cutoff_rad_ - beam_rad);
    cos_cutoff_ = std::cos(cutoff_rad_);
    cos_beam_ = std::cos(beam_rad);
    // ∫ falloff dω = 2π ∫ falloff(θ) sin θ dθ, by the midpoint rule (smooth: 4096 steps are exact to 1e-7).
    double s = 0;
    const int n = 4096;
    for (int i = 0; i < n; ++i) {
        const double theta = (i + 0.5) * cutoff_rad_ / n;
        const double f = theta <= beam_rad ? 1.0 : (cutoff_rad_ - theta) * inv_transition_;
        s += f * std::sin(theta);
    }
    falloff_solid_angle_ = float(2 * M_PI * s * cutoff_rad_ / n);
}

float SpotLight::falloff(const Vec3 &w) const {
    const float cos_theta = dot(w, axis_);
    if (!(cos_theta > cos_cutoff_)) return 0.f;
    if (cos_theta >= cos_beam_) return 1.f;
    return (cutoff_rad_ - std::acos(std::min(cos_theta, 1.f))) * inv_transition_;
}

DirectionSample SpotLight::sample_direction(const Vec3 &ref, Vec2, Color &radiance) const {
    float dist2;
    const DirectionSample ds = direction_sample_to_point(position_, ref, dist2);
    radiance = intensity_ * (falloff(-ds.d) / dist2);  // as a point light's, through the falloff
    return ds;
}

EmissionSample SpotLight::sample_emission(Vec2, Vec2 u_dir) const {
    EmissionSample es;
    es.p = position_;
    const Vec3 local = square_to_uniform_cone(u_dir, cos_cutoff_);
    es.ray = Ray{position_, normalize(to_world_.vector(local)), 0.f, kInfinity};
    es.radiance = intensity_ * falloff(es.ray.d);
    es.pdf_pos = 1.f;
    es.pdf_dir = square_to_uniform_cone_pdf(cos_cutoff_);
    return es;
}

EmissionDensity SpotLight::pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &w) const {
    return {1.f, dot(w, axis_) > cos_cutoff_ ? square_to_uniform_cone_pdf(cos_cutoff_) : 0.f};
}

std::optional<LightBounds> SpotLight::bounds() const {
    LightBounds b;
    b.bounds.expand(position_);
    b.normals = DirectionCone{axis_, 1.f};
    b.cos_theta_e = cos_cutoff_;
    b.phi = luminance(power());
    return b;
}

}  // namespace neepp
