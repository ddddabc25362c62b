// Mitsuba's `twosided`: makes a one-sided BSDF (or a pair, front and back) reflect on both sides by
// mirroring directions seen from below into the upper hemisphere.
#pragma once
#include "neepp/base/bsdf.h"

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
// Mitsuba's `polarizer` as its RGB variants render it is the same pass-through carrying scale ×
// transmittance = 0.5 × its `transmittance`, whatever its angle `theta` (only polarized variants see it).
class NullBSDF final : public BSDF {
public:
    NullBSDF() = default;
    NullBSDF(TexturePtr transmittance, float scale) : transmittance_(std::move(transmittance)), scale_(scale) {}
    Color eval(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const override { return Color(0.f); }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const override { return 0.f; }
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float, Vec2) const override {
        return pass_through(wi, 1.f, transmittance_ ? transmittance_->eval(si) * scale_ : Color(1.f));
    }
    uint32_t flags() const override { return BSDFNull; }
    bool needs_tangents() const override { return false; }
    void prefetch(const SurfaceInteraction &si) const override { prefetch_textures(si, transmittance_); }

    // The null event: wo = -wi, chosen with probability pdf, carrying weight.
    static BSDFSample pass_through(const Vec3 &wi, float pdf, Color weight) {
        BSDFSample bs;
        bs.wo = -wi;
        bs.pdf = pdf;
        bs.sampled_flags = BSDFNull;
        bs.weight = weight;
        return bs;
    }

private:
    TexturePtr transmittance_;  // null: 1
    float scale_ = 1.f;
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
