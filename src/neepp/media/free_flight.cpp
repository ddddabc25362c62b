#include "neepp/media/free_flight.h"

#include <algorithm>
#include <cmath>
#include "neepp/base/interaction.h"
#include "neepp/sampling/sampler.h"

namespace neepp {

FreeFlight sample_free_flight(const Medium &medium, const Ray &ray, float t_end, int channel, Sampler &sampler) {
    FreeFlight f;
    Ray r = ray;
    r.tmax = std::min(ray.tmax, t_end);
    float t0, t1;
    if (!medium.overlap(r, t0, t1)) return f;
    const Color majorant = medium.majorant(ray.d);
    const float m = majorant[channel];
    const float t = m > 0 ? t0 - std::log(1.f - sampler.next_1d()) / m : kInfinity;
    if (!(t < t1)) return passed_free_flight(medium, ray, t_end);
    f.t = t;
    const Color tr = vexp(-majorant * (t - t0));
    const MediumCoefficients c = medium.at(r.at(t), ray.d);
    const Color sigma_n = majorant - c.sigma_t;
    float p_null = 0.f;
    for (int k = 0; k < 3; ++k)
        if (majorant[k] > 0) p_null += sigma_n[k] / majorant[k] / 3.f;
    const bool null = p_null > 0.f && sampler.next_1d() < p_null;
    f.event = null ? FreeFlight::Null : FreeFlight::Real;
    f.f = tr * (null ? sigma_n : c.sigma_s);
    f.pdf = tr * majorant * (null ? p_null : 1.f - p_null);
    return f;
}

FreeFlight passed_free_flight(const Medium &medium, const Ray &ray, float t_end) {
    FreeFlight f;
    Ray r = ray;
    r.tmax = std::min(ray.tmax, t_end);
    float t0, t1;
    if (medium.overlap(r, t0, t1)) f.f = f.pdf = vexp(-medium.majorant(ray.d) * (t1 - t0));
    return f;
}

}  // namespace neepp
