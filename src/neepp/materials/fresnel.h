// Fresnel equations and the reflection/refraction helpers that go with them, following Mitsuba 3's
// render/fresnel.h so that every BSDF built on them reproduces Mitsuba's numbers.
#pragma once
#include "neepp/math/vec.h"

namespace neepp {

struct FresnelResult {
    float r;            // unpolarized reflectance
    float cos_theta_t;  // cosine of the refracted direction, signed opposite to cos_theta_i (0 under TIR)
    float eta_it;       // relative IOR along the direction of travel (transmitted side / incident side)
    float eta_ti;       // its reciprocal: the scale applied to the x, y components of the refracted direction
};

// Dielectric interface. eta = interior / exterior IOR; cos_theta_i < 0 means arriving from the interior.
FresnelResult fresnel_dielectric(float cos_theta_i, float eta);

// Conductor with complex IOR eta + i k, light arriving from outside (cos_theta_i >= 0).
float fresnel_conductor(float cos_theta_i, float eta, float k);
Color fresnel_conductor(float cos_theta_i, const Color &eta, const Color &k);

// Hemispherical average of the dielectric reflectance ("Fdr"), Mitsuba's fitted approximation.
float fresnel_diffuse_reflectance(float eta);

// Mirror reflection about the local normal (0, 0, 1).
inline Vec3 reflect_local(const Vec3 &wi) { return {-wi.x, -wi.y, wi.z}; }

// Refraction about the local normal; cos_theta_t and eta_ti come from fresnel_dielectric().
inline Vec3 refract_local(const Vec3 &wi, float cos_theta_t, float eta_ti) {
    return {-eta_ti * wi.x, -eta_ti * wi.y, cos_theta_t};
}

// Refraction about a microfacet normal m.
inline Vec3 refract(const Vec3 &wi, const Vec3 &m, float cos_theta_t, float eta_ti) {
    return m * (dot(wi, m) * eta_ti + cos_theta_t) - wi * eta_ti;
}

}  // namespace neepp
