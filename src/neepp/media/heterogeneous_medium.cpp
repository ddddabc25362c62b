#include "neepp/media/heterogeneous_medium.h"

#include <algorithm>
#include "neepp/base/interaction.h"

namespace neepp {

HeterogeneousMedium::HeterogeneousMedium(std::shared_ptr<const Volume> sigma_t, std::shared_ptr<const Volume> albedo,
                                         float scale, std::shared_ptr<const PhaseFunction> phase_function)
    : sigma_t_(std::move(sigma_t)), albedo_(std::move(albedo)), scale_(scale), bounds_(sigma_t_->bounds()) {
    phase = std::move(phase_function);
    majorant_ = scale * sigma_t_->max() * phase->max_projected_area();
}

bool HeterogeneousMedium::overlap(const Ray &ray, float &t0, float &t1) const {
    // The ray against the box, slab by slab.
    t0 = ray.tmin, t1 = ray.tmax;
    for (int a = 0; a < 3; ++a) {
        const float inv = 1.f / ray.d[a];
        float near = (bounds_.lo[a] - ray.o[a]) * inv, far = (bounds_.hi[a] - ray.o[a]) * inv;
        if (near > far) std::swap(near, far);
        if (!(near <= far)) {  // a ray along the slab's planes: inside them or not at all
            if (ray.o[a] < bounds_.lo[a] || ray.o[a] > bounds_.hi[a]) return false;
            continue;
        }
        t0 = std::max(t0, near);
        t1 = std::min(t1, far);
    }
    return t0 < t1;
}

MediumCoefficients HeterogeneousMedium::at(const Vec3 &p, const Vec3 &d) const {
    MediumCoefficients c;
    c.sigma_t = sigma_t_->eval(p) * (scale_ * phase->projected_area(p, d));
    c.sigma_s = c.sigma_t * albedo_->eval(p);
    return c;
}

}  // namespace neepp
