// Mitsuba 3's `homogeneous` medium: the same sigma_t = scale · sigma_t and sigma_s = albedo · sigma_t
// everywhere, filling whatever the shapes that name it bound.
#pragma once
#include "neepp/base/medium.h"

namespace neepp {

class HomogeneousMedium final : public Medium {
public:
    // sigma_t already scaled; albedo in [0, 1] per channel.
    HomogeneousMedium(Color sigma_t, Color albedo);
    bool overlap(const Ray &ray, float &t0, float &t1) const override;
    Color majorant() const override { return coefficients_.sigma_t; }
    MediumCoefficients at(const Vec3 &) const override { return coefficients_; }
    bool homogeneous() const override { return true; }

private:
    MediumCoefficients coefficients_;
};

}  // namespace neepp
