#include "neepp/materials/fresnel.h"

namespace neepp {

FresnelResult fresnel_dielectric(float cos_theta_i, float eta) {
    bool outside = cos_theta_i >= 0.f;
    float eta_it = outside ? eta : 1.f / eta, eta_ti = outside ? 1.f / eta : eta;

    // Snell's law gives the squared cosine of the refracted angle; negative means total internal reflection.
    float cos_theta_t_sqr = 1.f - (1.f - cos_theta_i * cos_theta_i) * (eta_ti * eta_ti);
    float cos_i = std::abs(cos_theta_i), cos_t = safe_sqrt(cos_theta_t_sqr);

    float a_s = (cos_i - eta_it * cos_t) / (cos_i + eta_it * cos_t);
    float a_p = (cos_t - eta_it * cos_i) / (cos_t + eta_it * cos_i);
    float r = 0.5f * (a_s * a_s + a_p * a_p);
    // Index-matched interfaces reflect nothing; grazing incidence reflects everything (avoids 0/0 above).
    if (eta == 1.f) r = 0.f;
    else if (cos_i == 0.f) r = 1.f;

    // The refracted ray leaves on the other side; signbit keeps Mitsuba's mulsign_neg behaviour for -0.
    return {r, std::signbit(cos_theta_i) ? cos_t : -cos_t, eta_it, eta_ti};
}

float fresnel_conductor(float cos_theta_i, float eta, float k) {
    // Moeller, "Optics" (1988), as in Mitsuba: closed form without complex arithmetic.
    float cos2 = cos_theta_i * cos_theta_i, sin2 = 1.f - cos2, sin4 = sin2 * sin2;
    float temp_1 = eta * eta - k * k - sin2;
    float a2_plus_b2 = safe_sqrt(temp_1 * temp_1 + 4.f * k * k * eta * eta);
    float a = safe_sqrt(0.5f * (a2_plus_b2 + temp_1));

    float term_1 = a2_plus_b2 + cos2, term_2 = 2.f * cos_theta_i * a;
    float r_s = (term_1 - term_2) / (term_1 + term_2);
    float term_3 = a2_plus_b2 * cos2 + sin4, term_4 = term_2 * sin2;
    float r_p = r_s * (term_3 - term_4) / (term_3 + term_4);
    return 0.5f * (r_s + r_p);
}

Color fresnel_conductor(float cos_theta_i, const Color &eta, const Color &k) {
    return {fresnel_conductor(cos_theta_i, eta.x, k.x), fresnel_conductor(cos_theta_i, eta.y, k.y),
            fresnel_conductor(cos_theta_i, eta.z, k.z)};
}

float fresnel_diffuse_reflectance(float eta) {
    float inv_eta = 1.f / eta;
    if (eta < 1.f) {
        // Egan and Hilgeman (1973): accurate for eta < 1 (i.e. 1/eta in the usual IOR range).
        return 0.0636f * inv_eta + (eta * (eta * -1.4399f + 0.7099f) + 0.6681f);
    }
    // d'Eon and Irving (2011): polynomial in 1/eta, accurate for large IORs.
    float x = inv_eta;
    return 0.919317f + x * (-3.4793f + x * (6.75335f + x * (-7.80989f + x * (4.98554f + x * -1.36881f))));
}

}  // namespace neepp
