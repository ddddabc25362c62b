// Mitsuba 3's `heterogeneous` medium: sigma_t = scale · a volume (a density grid), sigma_s = sigma_t ·
// albedo (a volume too), inside the box of the sigma_t volume and nowhere else. Its majorant is one grey
// number, scale times the volume's largest value, everywhere (as Mitsuba's: no grid of local majorants),
// times the phase function's largest projected area (a microflake one: Mitsuba leaves that factor out,
// which bounds the extinction only where S's eigenvalues are at most 1).
#pragma once
#include <memory>
#include "neepp/base/medium.h"
#include "neepp/media/volume.h"

namespace neepp {

class HeterogeneousMedium final : public Medium {
public:
    HeterogeneousMedium(std::shared_ptr<const Volume> sigma_t, std::shared_ptr<const Volume> albedo, float scale,
                        std::shared_ptr<const PhaseFunction> phase);
    bool overlap(const Ray &ray, float &t0, float &t1) const override;
    Color majorant(const Vec3 &) const override { return Color(majorant_); }
    MediumCoefficients at(const Vec3 &p, const Vec3 &d) const override;
    bool homogeneous() const override { return false; }

private:
    std::shared_ptr<const Volume> sigma_t_, albedo_;
    float scale_, majorant_;
    BBox bounds_;
};

}  // namespace neepp
