// Mitsuba 3's `homogeneous` medium: the same sigma_t = scale · sigma_t and sigma_s = albedo · sigma_t
// everywhere, filling whatever the shapes that name it bound.
#pragma once
#include <memory>
#include "neepp/base/medium.h"
#include "neepp/media/volume.h"

namespace neepp {

class HomogeneousMedium final : public Medium {
public:
    // sigma_t already scaled; albedo in [0, 1] per channel, which may vary in space (a volume).
    HomogeneousMedium(Color sigma_t, std::shared_ptr<const Volume> albedo);
    bool overlap(const Ray &ray, float &t0, float &t1) const override;
    Color majorant() const override { return sigma_t_; }
    MediumCoefficients at(const Vec3 &p) const override { return {sigma_t_, sigma_t_ * albedo_->eval(p)}; }
    bool homogeneous() const override { return true; }

private:
    Color sigma_t_;
    std::shared_ptr<const Volume> albedo_;
};

}  // namespace neepp
