// Mitsuba 3's `blendphase`: a mixture of two phase functions whose weight may vary through the medium.
#pragma once
#include <memory>
#include "neepp/base/medium.h"
#include "neepp/media/volume.h"

namespace neepp {

// (1 - w) first + w second, with w the weight volume at the scattering point, clipped to [0, 1] (a
// colour's luminance, as Mitsuba's scalar lookup of a 3-channel volume): w = 0 is the first alone.
// Sampling picks one of the two by w and returns the mixture's density and value over density, so that
// its weight is exact whichever was picked.
class BlendPhase final : public PhaseFunction {
public:
    BlendPhase(std::shared_ptr<const PhaseFunction> first, std::shared_ptr<const PhaseFunction> second,
               std::shared_ptr<const Volume> weight);
    float eval(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const override;
    PhaseSample sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const override;
    float weight(const Vec3 &p) const;  // the second's share at p

private:
    std::shared_ptr<const PhaseFunction> first_, second_;
    std::shared_ptr<const Volume> weight_;
};

}  // namespace neepp
