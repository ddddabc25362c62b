// Mitsuba 3's `homogeneous` medium: the same sigma_t = scale · sigma_t and sigma_s = albedo · sigma_t
// everywhere, filling whatever the shapes that name it bound. With a microflake phase function sigma_t is
// also times its projected area along the direction of travel, the same everywhere only where its S is
// (the loader sees to that).
#pragma once
#include <memory>
#include "neepp/base/medium.h"
#include "neepp/media/volume.h"

namespace neepp {

class HomogeneousMedium final : public Medium {
public:
    // sigma_t already scaled; albedo in [0, 1] per channel, which may vary in space (a volume).
    HomogeneousMedium(Color sigma_t, std::shared_ptr<const Volume> albedo, std::shared_ptr<const PhaseFunction> phase);
    bool overlap(const Ray &ray, float &t0, float &t1) const override;
    Color majorant(const Vec3 &d) const override { return sigma_t_ * phase->projected_area(Vec3(0.f), d); }
    MediumCoefficients at(const Vec3 &p, const Vec3 &d) const override {
        const Color sigma_t = majorant(d);
        return {sigma_t, sigma_t * albedo_->eval(p)};
    }
    bool homogeneous() const override { return true; }

private:
    Color sigma_t_;
    std::shared_ptr<const Volume> albedo_;
};

}  // namespace neepp
