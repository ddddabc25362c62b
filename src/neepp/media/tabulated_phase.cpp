#include "neepp/media/tabulated_phase.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include "neepp/math/frame.h"
#include "neepp/math/warp.h"

namespace neepp {

TabulatedPhase::TabulatedPhase(std::vector<float> values) : values_(std::move(values)) {
    if (values_.size() < 2)
        throw std::invalid_argument("a tabulated phase function needs at least two values (at cos_theta = -1 and 1), not " +
                                    std::to_string(values_.size()));
    for (float v : values_)
        if (!std::isfinite(v) || v < 0)
            throw std::invalid_argument("a tabulated phase function's values are finite and not negative, not " + std::to_string(v));
    segment_ = 2.0 / double(values_.size() - 1);
    double mass = 0;
    for (size_t i = 0; i + 1 < values_.size(); ++i) {
        mass += 0.5 * segment_ * (double(values_[i]) + double(values_[i + 1]));
        cdf_.push_back(mass);
    }
    if (!(mass > 0)) throw std::invalid_argument("a tabulated phase function's values are all zero");
    normalization_ = float(1.0 / mass);
}

float TabulatedPhase::density(float cos_theta) const {
    if (!(cos_theta >= -1.f && cos_theta <= 1.f)) return 0.f;
    const double x = (double(cos_theta) + 1.0) / segment_;
    const size_t i = std::min(size_t(x), values_.size() - 2);
    const double t = x - double(i);
    return float((1.0 - t) * values_[i] + t * values_[i + 1]) * normalization_;
}

// The density is per unit cosine; uniform in the azimuth, it is 1/(2 pi) of that per steradian.
float TabulatedPhase::eval(const Vec3 &, const Vec3 &wi, const Vec3 &wo) const {
    return density(-dot(wi, wo)) * kInv2Pi;
}

PhaseSample TabulatedPhase::sample(const Vec3 &, const Vec3 &wi, Vec2 u) const {
    // The segment: the first whose cumulative mass exceeds the scaled number, so that a segment without
    // mass is never chosen.
    const double target = double(u.x) * cdf_.back();
    const size_t i = std::min(size_t(std::upper_bound(cdf_.begin(), cdf_.end(), target) - cdf_.begin()), cdf_.size() - 1);
    const double before = i > 0 ? cdf_[i - 1] : 0.0;
    // Within it the density is y0 + (y1 - y0) t over t in [0, 1]; its mass up to t, y0 t + (y1 - y0) t^2 / 2,
    // equals m. The root in the form that has no cancellation, for a rising, falling or flat segment.
    const double y0 = values_[i], y1 = values_[i + 1], m = std::max(0.0, (target - before) / segment_);
    const double root = std::sqrt(std::max(0.0, y0 * y0 + 2.0 * m * (y1 - y0)));
    const double t = y0 + root > 0 ? std::clamp(2.0 * m / (y0 + root), 0.0, 1.0) : 0.0;
    const float cos_theta = std::clamp(float(-1.0 + (double(i) + t) * segment_), -1.f, 1.f);
    const float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    const float phi = 2.f * kPi * u.y;
    // About the direction of travel, -wi: cos_theta = 1 goes straight on.
    const Vec3 wo = Frame(-wi).to_world(Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta));
    return {wo, density(cos_theta) * kInv2Pi, 1.f};
}

}  // namespace neepp
