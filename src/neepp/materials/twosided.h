// Mitsuba's `twosided`: makes a one-sided BSDF (or a pair, front and back) reflect on both sides by
// mirroring directions seen from below into the upper hemisphere.
#pragma once
#include "neepp/materials/bsdf.h"

namespace neepp {

class TwoSidedBSDF final : public BSDF {
public:
    TwoSidedBSDF(BSDFPtr front, BSDFPtr back) : front_(std::move(front)), back_(back ? std::move(back) : front_) {}
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return front_->flags() | back_->flags(); }
    void prefetch(const SurfaceInteraction &si) const override { (si.wi.z >= 0 ? front_ : back_)->prefetch(si); }
    bool needs_tangents() const override { return front_->needs_tangents() || back_->needs_tangents(); }

private:
    BSDFPtr front_, back_;
};

// Mitsuba's `mask`: an opacity texture; with probability 1 - opacity light passes straight through
// (a null, delta-transmission event), otherwise the nested BSDF scatters it.
// Mitsuba's `null`: the surface does not interact with light (a shape that only bounds something, an
// emitter that does not reflect): every ray passes straight through, as a mask of opacity 0 would let it.
class NullBSDF final : public BSDF {
public:
    Color eval(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const override { return Color(0.f); }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const override { return 0.f; }
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &, const Vec3 &wi, float, Vec2) const override {
        BSDFSample bs;
        bs.wo = -wi;
        bs.pdf = 1.f;
        bs.sampled_flags = BSDFNull;
        bs.weight = Color(1.f);
        return bs;
    }
    uint32_t flags() const override { return BSDFNull; }
};

// Mitsuba's `polarizer` (a linear polarizer) as its RGB variants render it: with unpolarized light every
// ray passes straight through carrying half the `transmittance` (Mitsuba: 0.5 * transmittance), whatever
// the polarizer's angle `theta`; only polarized variants see the angle.
class PolarizerBSDF final : public BSDF {
public:
    explicit PolarizerBSDF(TexturePtr transmittance) : transmittance_(std::move(transmittance)) {}
    Color eval(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const override { return Color(0.f); }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const override { return 0.f; }
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float, Vec2) const override {
        BSDFSample bs;
        bs.wo = -wi;
        bs.pdf = 1.f;
        bs.sampled_flags = BSDFNull;
        bs.weight = transmittance_->eval(si) * 0.5f;
        return bs;
    }
    uint32_t flags() const override { return BSDFNull; }
    void prefetch(const SurfaceInteraction &si) const override { transmittance_->prefetch(si); }

private:
    TexturePtr transmittance_;
};

class MaskBSDF final : public BSDF {
public:
    MaskBSDF(TexturePtr opacity, BSDFPtr nested) : opacity_(std::move(opacity)), nested_(std::move(nested)) {}
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return nested_->flags() | BSDFNull; }
    void prefetch(const SurfaceInteraction &si) const override {
        opacity_->prefetch(si);
        nested_->prefetch(si);
    }
    bool needs_tangents() const override { return nested_->needs_tangents(); }

private:
    float opacity(const SurfaceInteraction &si) const { return std::clamp(opacity_->eval_1(si), 0.f, 1.f); }
    TexturePtr opacity_;
    BSDFPtr nested_;
};

}  // namespace neepp
