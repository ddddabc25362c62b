#include "neepp/media/blend_phase.h"

#include <algorithm>

namespace neepp {

BlendPhase::BlendPhase(std::shared_ptr<const PhaseFunction> first, std::shared_ptr<const PhaseFunction> second,
                       std::shared_ptr<const Volume> weight)
    : first_(std::move(first)), second_(std::move(second)), weight_(std::move(weight)) {}

float BlendPhase::weight(const Vec3 &p) const {
    const Color c = weight_->eval(p);
    // A grey value is itself: luminance's coefficients sum to 1 only up to rounding, and a weight of
    // exactly 0 or 1 should leave the other phase function out entirely.
    const float w = c.x == c.y && c.y == c.z ? c.x : luminance(c);
    return std::clamp(w, 0.f, 1.f);
}

float BlendPhase::eval(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const {
    const float w = weight(p);
    return (1.f - w) * first_->eval(p, wi, wo) + w * second_->eval(p, wi, wo);
}

float BlendPhase::pdf(const Vec3 &p, const Vec3 &wi, const Vec3 &wo) const {
    const float w = weight(p);
    return (1.f - w) * first_->pdf(p, wi, wo) + w * second_->pdf(p, wi, wo);
}

PhaseSample BlendPhase::sample(const Vec3 &p, const Vec3 &wi, Vec2 u) const {
    const float w = weight(p);
    // u.x picks the lobe and, rescaled to [0, 1) within its share, is the lobe's own first number (one
    // number fewer than Mitsuba draws; the same distribution).
    const bool second = u.x < w;
    const float u_lobe = second ? u.x / w : (u.x - w) / (1.f - w);
    const PhaseFunction &picked = second ? *second_ : *first_, &other = second ? *first_ : *second_;
    const PhaseSample s = picked.sample(p, wi, Vec2(std::min(u_lobe, kOneMinusEpsilon), u.y));
    if (!(s.pdf > 0)) return {};
    const float w_picked = second ? w : 1.f - w, w_other = 1.f - w_picked;
    const float pdf = w_picked * s.pdf + w_other * other.pdf(p, wi, s.wo);
    const float value = w_picked * s.weight * s.pdf + w_other * other.eval(p, wi, s.wo);
    if (!(pdf > 0)) return {};
    return {s.wo, pdf, value / pdf};
}

}  // namespace neepp
