#include "neepp/media/phase_functions.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include "neepp/math/frame.h"
#include "neepp/math/warp.h"

namespace neepp {

float IsotropicPhase::eval(const Vec3 &, const Vec3 &, const Vec3 &) const { return kInv4Pi; }
float IsotropicPhase::pdf(const Vec3 &, const Vec3 &, const Vec3 &) const { return kInv4Pi; }

PhaseSample IsotropicPhase::sample(const Vec3 &, const Vec3 &, Vec2 u) const {
    return {square_to_uniform_sphere(u), kInv4Pi, 1.f};
}

HenyeyGreensteinPhase::HenyeyGreensteinPhase(float g) : g_(g) {
    if (!(g > -1.f && g < 1.f))
        throw std::invalid_argument("the Henyey-Greenstein g must lie strictly between -1 and 1, not " + std::to_string(g));
}

namespace {

// The lobe's density at cos_theta, the cosine between the direction of travel and the new direction.
float hg(float g, float cos_theta) {
    const float denom = 1.f + g * g - 2.f * g * cos_theta;
    return kInv4Pi * (1.f - g * g) / (denom * std::sqrt(std::max(denom, 0.f)));
}

}  // namespace

float HenyeyGreensteinPhase::eval(const Vec3 &, const Vec3 &wi, const Vec3 &wo) const { return hg(g_, -dot(wi, wo)); }

PhaseSample HenyeyGreensteinPhase::sample(const Vec3 &, const Vec3 &wi, Vec2 u) const {
    // The inverse of the lobe's distribution of cos_theta (Mitsuba's and pbrt's), about the direction of
    // travel -wi.
    float cos_theta;
    if (std::abs(g_) < 1e-3f) {
        cos_theta = 1.f - 2.f * u.x;
    } else {
        const float s = (1.f - g_ * g_) / (1.f - g_ + 2.f * g_ * u.x);
        cos_theta = (1.f + g_ * g_ - s * s) / (2.f * g_);
    }
    cos_theta = std::clamp(cos_theta, -1.f, 1.f);
    const float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    const float phi = 2.f * kPi * u.y;
    const Frame frame(-wi);
    const Vec3 wo = frame.to_world(Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta));
    return {wo, hg(g_, cos_theta), 1.f};
}

namespace {

float rayleigh(float cos_theta) { return 3.f / (16.f * kPi) * (1.f + cos_theta * cos_theta); }

}  // namespace

float RayleighPhase::eval(const Vec3 &, const Vec3 &wi, const Vec3 &wo) const { return rayleigh(dot(wi, wo)); }

PhaseSample RayleighPhase::sample(const Vec3 &, const Vec3 &wi, Vec2 u) const {
    // The distribution of cos_theta is u = (3 c + c^3 + 4) / 8, the cubic c^3 + 3 c - 4 (2u - 1) = 0, whose
    // one real root Cardano's formula gives (as Mitsuba samples it). The lobe is symmetric, so which way
    // about wi the cosine is measured does not matter.
    const float z = 2.f * (2.f * u.x - 1.f), root = std::sqrt(z * z + 1.f);
    const float cos_theta = std::clamp(std::cbrt(z + root) + std::cbrt(z - root), -1.f, 1.f);
    const float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    const float phi = 2.f * kPi * u.y;
    const Vec3 wo = Frame(wi).to_world(Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta));
    return {wo, rayleigh(cos_theta), 1.f};
}

}  // namespace neepp
