// Mitsuba 3's phase functions `isotropic` and `hg` (Henyey-Greenstein).
#pragma once
#include "neepp/base/medium.h"

namespace neepp {

class IsotropicPhase final : public PhaseFunction {
public:
    float eval(const Vec3 &, const Vec3 &) const override;
    float pdf(const Vec3 &, const Vec3 &) const override;
    PhaseSample sample(const Vec3 &wi, Vec2 u) const override;
};

// Henyey and Greenstein's lobe of mean cosine g between the direction light travelled in (-wi) and wo:
// g > 0 scatters forward, g < 0 back, 0 is isotropic. Sampled exactly, so value = pdf and the weight is 1.
class HenyeyGreensteinPhase final : public PhaseFunction {
public:
    // Throws std::invalid_argument unless -1 < g < 1.
    explicit HenyeyGreensteinPhase(float g);
    float eval(const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const Vec3 &wi, const Vec3 &wo) const override { return eval(wi, wo); }
    PhaseSample sample(const Vec3 &wi, Vec2 u) const override;
    float g() const { return g_; }

private:
    float g_;
};

}  // namespace neepp
