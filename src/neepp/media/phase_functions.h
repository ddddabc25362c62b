// Mitsuba 3's analytic phase functions: `isotropic`, `hg` (Henyey-Greenstein) and `rayleigh`. Each is the
// same everywhere in its medium, so the point p of the interface is not read.
#pragma once
#include "neepp/base/medium.h"

namespace neepp {

class IsotropicPhase final : public PhaseFunction {
public:
    float eval(const Vec3 &, const Vec3 &, const Vec3 &) const override;
    float pdf(const Vec3 &, const Vec3 &, const Vec3 &) const override;
    PhaseSample sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const override;
};

// Henyey and Greenstein's lobe of mean cosine g between the direction light travelled in (-wi) and wo:
// g > 0 scatters forward, g < 0 back, 0 is isotropic. Sampled exactly, so value = pdf and the weight is 1.
class HenyeyGreensteinPhase final : public PhaseFunction {
public:
    // Throws std::invalid_argument unless -1 < g < 1.
    explicit HenyeyGreensteinPhase(float g);
    float eval(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override { return eval(p, wi, wo); }
    PhaseSample sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const override;
    float g() const { return g_; }

private:
    float g_;
};

// Scattering by particles much smaller than the wavelength (air): 3/(16 pi) (1 + cos^2), as much backward
// as forward. Sampled exactly (the cubic its distribution gives has a closed-form root), weight 1.
class RayleighPhase final : public PhaseFunction {
public:
    float eval(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override { return eval(p, wi, wo); }
    PhaseSample sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const override;
};

}  // namespace neepp
