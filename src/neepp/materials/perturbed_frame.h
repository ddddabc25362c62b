// Base of the BSDFs that shade a nested BSDF in a perturbed shading frame (Mitsuba's `bumpmap` and
// `normalmap`): the derived class says where the perturbed normal points; the rules both share live here,
// once: Mitsuba 3's two defaults, `flip_invalid_normals` and `use_shadowing_function`, the side test of
// the direction toward the light, and the correction that light tracing and BDPT need for the frame.
#pragma once
#include "neepp/base/bsdf.h"

namespace neepp {

class PerturbedFrameBSDF : public BSDF {
public:
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const final;
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const final;
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const final;
    BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                      Vec2 u2) const final;
    uint32_t flags() const final { return nested_->flags(); }
    void prefetch(const SurfaceInteraction &si) const final {  // the perturbed frame keeps si's uv
        map_->prefetch(si);
        nested_->prefetch(si);
    }
    // The perturbed frame is oriented by the tangents (dp/du for a bump map, the shading frame's s for a
    // tangent-space normal map), so hits need them.
    bool needs_tangents() const final { return true; }
    // The perturbed shading frame, in world space (for wi, local to si's frame, when normals are flipped).
    virtual Frame perturbed_frame(const SurfaceInteraction &si, const Vec3 &wi) const = 0;

protected:
    // flip_invalid_normals: a perturbed normal facing away from wi is mirrored about the unperturbed one;
    // use_shadowing_function: the response is attenuated toward grazing directions by the microfacet-
    // based shadowing term of Estevez et al. 2019 (Ray Tracing Gems, "A Microfacet-Based Shadowing
    // Function to Solve the Bump Terminator Problem"). Both on by default, as in Mitsuba 3.
    PerturbedFrameBSDF(TexturePtr map, BSDFPtr nested, bool flip_invalid_normals, bool use_shadowing_function)
        : map_(std::move(map)), nested_(std::move(nested)), flip_invalid_normals_(flip_invalid_normals),
          shadowing_(use_shadowing_function) {}
    // The world frame around the perturbed normal n (local to si's frame, any nonzero length), flipped
    // toward wi when flip_invalid_normals, with s the part of `tangent` (world) orthogonal to it. si's own
    // frame where n is degenerate.
    Frame oriented_frame(const SurfaceInteraction &si, const Vec3 &wi, Vec3 n, const Vec3 &tangent) const;
    const Texture &map() const { return *map_; }

private:
    // Copy of si with the perturbed frame, and a map from si's local directions into it.
    SurfaceInteraction perturbed(const SurfaceInteraction &si, const Vec3 &wi, Vec3 &wi_p) const;
    // Mitsuba's shadowing term for wo (local to si's frame) under perturbed normal np (local too).
    float shadowing(const Vec3 &np, const Vec3 &wo) const;
    TexturePtr map_;
    BSDFPtr nested_;
    bool flip_invalid_normals_, shadowing_;
};

}  // namespace neepp
