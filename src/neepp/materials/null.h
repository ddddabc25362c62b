// Mitsuba's `null`: the surface does not interact with light (a shape that only bounds something, an
// emitter that does not reflect): every ray passes straight through, as a mask of opacity 0 would let it.
// Mitsuba's `polarizer` as its RGB variants render it is the same pass-through carrying scale ×
// transmittance = 0.5 × its `transmittance`, whatever its angle `theta` (only polarized variants see it).
#pragma once
#include "neepp/base/bsdf.h"

namespace neepp {

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
    Color null_transmission(const SurfaceInteraction &si, const Vec3 &) const override {
        return transmittance_ ? transmittance_->eval(si) * scale_ : Color(1.f);
    }
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

}  // namespace neepp
