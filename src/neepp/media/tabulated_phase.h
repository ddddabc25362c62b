// Mitsuba 3's `tabphase`: a phase function given as a table of values.
#pragma once
#include <vector>
#include "neepp/base/medium.h"

namespace neepp {

// A density over cos_theta tabulated at n >= 2 cosines evenly spaced from -1 to 1, linear between them and
// normalised, and uniform in the azimuth. The cosine is the physicists' one, as Mitsuba reads the table:
// between wo and the direction light travelled (-wi), so the last value is for forward scattering.
// Sampled exactly (each segment's distribution is inverted in closed form), weight 1.
class TabulatedPhase final : public PhaseFunction {
public:
    // Throws std::invalid_argument with fewer than two values, one that is negative or not finite, or
    // all zero.
    explicit TabulatedPhase(std::vector<float> values);
    float eval(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override { return eval(p, wi, wo); }
    PhaseSample sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const override;

private:
    // The normalised density per unit cosine at cos_theta (zero outside [-1, 1]).
    float density(float cos_theta) const;

    std::vector<float> values_;
    std::vector<double> cdf_;  // cdf_[i]: the unnormalised mass of the segments 0..i
    double segment_ = 0;       // the width of a segment in cos_theta
    float normalization_ = 0;  // 1 / total mass
};

}  // namespace neepp
