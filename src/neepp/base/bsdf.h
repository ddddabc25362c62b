// The BSDF interface. Directions are in the local shading frame (z = shading normal).
//
// Conventions (Mitsuba 3's): `wi` points toward the previous path vertex (toward the camera when tracing
// radiance), `wo` toward the next one. eval() returns f(wi, wo) * |cos(theta_o)|. The TransportMode tells
// whether radiance (camera paths) or importance (light paths, for BDPT and light tracing) is carried: it
// matters for refraction (the eta^2 radiance scaling) and for shading-normal corrections. pdf(wi, wo) is
// the solid-angle density of sampling wo given wi; the reverse density, needed by BDPT's MIS, is pdf with
// the arguments swapped and the mode flipped.
#pragma once
#include <cstdint>
#include <memory>
#include "neepp/base/interaction.h"
#include "neepp/base/texture.h"

namespace neepp {

enum class TransportMode { Radiance, Importance };

inline TransportMode flip(TransportMode m) {
    return m == TransportMode::Radiance ? TransportMode::Importance : TransportMode::Radiance;
}

// Lobe flags, as Mitsuba's BSDFFlags.
enum BSDFFlags : uint32_t {
    BSDFNone = 0,
    BSDFNull = 1u << 0,                 // passes light straight through (mask)
    BSDFDiffuseReflection = 1u << 1,
    BSDFDiffuseTransmission = 1u << 2,
    BSDFGlossyReflection = 1u << 3,
    BSDFGlossyTransmission = 1u << 4,
    BSDFDeltaReflection = 1u << 5,
    BSDFDeltaTransmission = 1u << 6,
    BSDFDiffuse = BSDFDiffuseReflection | BSDFDiffuseTransmission,
    BSDFGlossy = BSDFGlossyReflection | BSDFGlossyTransmission,
    BSDFSmooth = BSDFDiffuse | BSDFGlossy,  // lobes that next event estimation can evaluate
    BSDFDelta = BSDFNull | BSDFDeltaReflection | BSDFDeltaTransmission,
    BSDFReflection = BSDFDiffuseReflection | BSDFGlossyReflection | BSDFDeltaReflection,
    BSDFTransmission = BSDFNull | BSDFDiffuseTransmission | BSDFGlossyTransmission | BSDFDeltaTransmission,
};

struct BSDFContext {
    TransportMode mode = TransportMode::Radiance;
};

struct BSDFSample {
    Vec3 wo;                  // sampled direction (local)
    float pdf = 0;            // solid-angle density (1 for a chosen delta lobe, times its selection probability)
    float eta = 1;            // relative index of refraction along the sampled direction (1 for reflection)
    uint32_t sampled_flags = BSDFNone;
    Color weight;             // f * |cos(theta_o)| / pdf (the delta case folded in); zero if sampling failed
    bool valid() const { return pdf > 0 && !is_black(weight); }
};

// f·|cos θo| and the density of sampling wo, for one pair of directions.
struct BSDFEval {
    Color f{0.f};
    float pdf = 0;
};

class BSDF {
public:
    virtual ~BSDF() = default;
    // --- What every BSDF defines.
    virtual Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const = 0;
    virtual float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const = 0;
    // eval and pdf at once: next event estimation needs both (the contribution and its MIS weight), and
    // they share the half vector, the microfacet terms and the texture lookups, which a BSDF that
    // overrides this computes once. Must equal {eval(), pdf()}; the default calls the two.
    virtual BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
        return {eval(ctx, si, wi, wo), pdf(ctx, si, wi, wo)};
    }
    // u1 chooses a lobe, u2 the direction within it.
    virtual BSDFSample sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                              Vec2 u2) const = 0;
    virtual uint32_t flags() const = 0;

    // --- Optional, each with a default that is right for every BSDF.
    // What passes straight through the surface, not scattered, for light arriving from wi (Mitsuba's
    // eval_null_transmission): what a ray toward a light through a participating medium keeps where it
    // crosses the surface. 0 for a surface opaque to such rays, which most are; the null BSDF's
    // transmittance, a thin dielectric's 1 - R, a mask's 1 - opacity.
    virtual Color null_transmission(const SurfaceInteraction &si, const Vec3 &wi) const { return Color(0.f); }
    // Speed hook: cache prefetch of the texture data that evaluating or sampling at si (seen from si.wi)
    // will read. A hint for batched integrators, issued well before shading; it never changes a result.
    virtual void prefetch(const SurfaceInteraction &si) const {}
    // Whether evaluating or sampling reads si.dpdu / si.dpdv or depends on which way the shading frame's
    // tangent points (bump maps, anisotropic roughness). A BSDF that does not may say false: its shapes'
    // hits then get a shading frame built from the normal alone, without the uv derivatives and the
    // Gram-Schmidt step, which is cheaper. The default, true, is right for every BSDF.
    virtual bool needs_tangents() const { return true; }
    bool has_flag(uint32_t f) const { return (flags() & f) != 0; }
};

// Base of BSDFs made only of delta lobes (smooth conductor, dielectrics): no direction has a finite
// density, so they can only be sampled, never evaluated.
class DeltaOnlyBSDF : public BSDF {
public:
    bool needs_tangents() const override { return false; }  // smooth interfaces: the normal alone
    Color eval(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const final {
        return Color(0.f);
    }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const final { return 0.f; }
};

// Base of BSDFs that evaluate f and its density together (microfacet BSDFs: both share the half vector,
// the microfacet terms and the texture lookups): eval and pdf are eval_pdf's two halves, so there is one
// implementation of the formulas.
class JointEvalBSDF : public BSDF {
public:
    Color eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const final {
        return eval_pdf(ctx, si, wi, wo).f;
    }
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const final {
        return eval_pdf(ctx, si, wi, wo).pdf;
    }
    BSDFEval eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override = 0;
};

using BSDFPtr = std::shared_ptr<const BSDF>;

}  // namespace neepp
