#include "neepp/lights/spot_light.h"

#include <cmath>
#include <stdexcept>
#include "neepp/math/warp.h"

namespace neepp {

SpotLight::SpotLight(const Transform &to_world, Color intensity_value, float cutoff_angle_deg, float beam_width_deg,
                     TexturePtr texture)
    : to_world_(to_world), intensity_(intensity_value), texture_(std::move(texture)) {
    if (!(cutoff_angle_deg > 0 && cutoff_angle_deg <= 180))
        throw std::invalid_argument("cutoff_angle must be in (0, 180] degrees");
    if (!(beam_width_deg >= 0 && beam_width_deg < cutoff_angle_deg))
        throw std::invalid_argument("beam_width must be in [0, cutoff_angle)");
    if (texture_ && texture_->is_constant())
        throw std::invalid_argument("a spot light's 'texture' must vary over uv (a bitmap, say): fold a constant into 'intensity'");
    position_ = to_world.point(Vec3(0.f));
    axis_ = normalize(to_world.vector(Vec3(0, 0, 1)));
    cutoff_rad_ = cutoff_angle_deg * kPi / 180.f;
    const float beam_rad = beam_width_deg * kPi / 180.f;
    inv_transition_ = 1.f / (cutoff_rad_ - beam_rad);
    cos_cutoff_ = std::cos(cutoff_rad_);
    cos_beam_ = std::cos(beam_rad);
    uv_factor_ = std::tan(cutoff_rad_);
    if (!texture_) {
        // ∫ falloff dω = 2π ∫ falloff(θ) sin θ dθ, by the midpoint rule (smooth: 4096 steps are exact to 1e-7).
        double s = 0;
        const int n = 4096;
        for (int i = 0; i < n; ++i) {
            const double theta = (i + 0.5) * cutoff_rad_ / n;
            const double f = theta <= beam_rad ? 1.0 : (cutoff_rad_ - theta) * inv_transition_;
            s += f * std::sin(theta);
        }
        power_ = intensity_ * float(2 * M_PI * s * cutoff_rad_ / n);
        return;
    }
    // With a texture the integrand has no symmetry: the midpoint rule over the square the uniform cone
    // warp maps onto the cone (area-preserving up to its constant density), fine enough for a bitmap's
    // texels to average out.
    const int n = 512;
    double sum[3] = {0, 0, 0};
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const Vec3 local = square_to_uniform_cone(Vec2((i + 0.5f) / n, (j + 0.5f) / n), cos_cutoff_);
            const Color c = intensity(normalize(to_world_.vector(local)));
            sum[0] += c.x, sum[1] += c.y, sum[2] += c.z;
        }
    const double scale = 1.0 / (double(n) * n * square_to_uniform_cone_pdf(cos_cutoff_));
    power_ = Color(float(sum[0] * scale), float(sum[1] * scale), float(sum[2] * scale));
}

float SpotLight::falloff(const Vec3 &w) const {
    const float cos_theta = dot(w, axis_);
    if (!(cos_theta > cos_cutoff_)) return 0.f;
    if (cos_theta >= cos_beam_) return 1.f;
    return (cutoff_rad_ - std::acos(std::min(cos_theta, 1.f))) * inv_transition_;
}

Color SpotLight::intensity(const Vec3 &w) const {
    const float f = falloff(w);
    if (!texture_ || f == 0.f) return intensity_ * f;  // no texture lookup outside the cone, as Mitsuba
    const Vec3 local = to_world_.inverse_vector(w);
    SurfaceInteraction si;
    si.uv = Vec2(0.5f + 0.5f * local.x / (local.z * uv_factor_), 0.5f + 0.5f * local.y / (local.z * uv_factor_));
    return intensity_ * texture_->eval(si) * f;
}

DirectionSample SpotLight::sample_direction(const Vec3 &ref, Vec2, Color &radiance) const {
    float dist2;
    const DirectionSample ds = direction_sample_to_point(position_, ref, dist2);
    radiance = intensity(-ds.d) / dist2;  // as a point light's, through the falloff and texture
    return ds;
}

EmissionSample SpotLight::sample_emission(Vec2, Vec2 u_dir) const {
    EmissionSample es;
    es.p = position_;
    const Vec3 local = square_to_uniform_cone(u_dir, cos_cutoff_);
    es.ray = Ray{position_, normalize(to_world_.vector(local)), 0.f, kInfinity};
    es.radiance = intensity(es.ray.d);
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
