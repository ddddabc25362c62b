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

// Mitsuba's `bumpmap`: perturbs the shading frame by the gradient of a height texture (times `scale`)
// and evaluates the nested BSDF in the perturbed frame.
class BumpMapBSDF final : public BSDF {
public:
    // flip_invalid_normals: a perturbed normal facing away from wi is mirrored about the unperturbed one;
    // use_shadowing_function: the response is attenuated toward grazing directions by the microfacet-
    // based shadowing term of Estevez et al. 2019 (Ray Tracing Gems, "A Microfacet-Based Shadowing
    // Function to Solve the Bump Terminator Problem"). Both on by default, as in Mitsuba 3.
    BumpMapBSDF(TexturePtr height, float scale, BSDFPtr nested, bool flip_invalid_normals = true,
                bool use_shadowing_function = true)
        : height_(std::move(height)), scale_(scale), nested_(std::move(nested)),
          flip_invalid_normals_(flip_invalid_normals), shadowing_(use_shadowing_function) {}
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const override;
    uint32_t flags() const override { return nested_->flags(); }
    void prefetch(const SurfaceInteraction &si) const override {  // the perturbed frame keeps si's uv
        height_->prefetch(si);
        nested_->prefetch(si);
    }
    bool needs_tangents() const override { return true; }  // the height gradient is taken along dp/du, dp/dv
    // The perturbed shading frame, in world space (for wi, local to si's frame, when normals are flipped).
    Frame perturbed_frame(const SurfaceInteraction &si, const Vec3 &wi) const;

private:
    // Copy of si with the perturbed frame, and a map from si's local directions into it.
    SurfaceInteraction perturbed(const SurfaceInteraction &si, const Vec3 &wi, Vec3 &wi_p) const;
    // Mitsuba's shadowing term for wo (local to si's frame) under perturbed normal np (local too).
    float shadowing(const Vec3 &np, const Vec3 &wo) const;
    TexturePtr height_;
    float scale_;
    BSDFPtr nested_;
    bool flip_invalid_normals_, shadowing_;
};

}  // namespace neepp
