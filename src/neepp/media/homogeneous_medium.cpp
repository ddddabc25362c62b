#include "neepp/media/homogeneous_medium.h"

#include "neepp/base/interaction.h"

namespace neepp {

HomogeneousMedium::HomogeneousMedium(Color sigma_t, std::shared_ptr<const Volume> albedo,
                                     std::shared_ptr<const PhaseFunction> phase_function)
    : sigma_t_(sigma_t), albedo_(std::move(albedo)) {
    phase = std::move(phase_function);
}

bool HomogeneousMedium::overlap(const Ray &ray, float &t0, float &t1) const {
    t0 = ray.tmin, t1 = ray.tmax;
    return t1 > t0;
}

}  // namespace neepp
