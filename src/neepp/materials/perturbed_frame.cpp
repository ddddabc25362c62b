#include "neepp/materials/perturbed_frame.h"

#include <algorithm>
#include <cmath>

namespace neepp {

Frame PerturbedFrameBSDF::oriented_frame(const SurfaceInteraction &si, const Vec3 &wi, Vec3 n,
                                         const Vec3 &tangent) const {
    const float len2 = squared_norm(n);
    if (!(len2 > 0) || !std::isfinite(len2)) return si.sh_frame;
    if (flip_invalid_normals_ && wi.z * dot(wi, n) <= 0.f) {
        // A normal that faces away from wi would shade the side wi is not on (black seams): mirror it
        // about the unperturbed normal, as Mitsuba 3 does.
        n.x = -n.x;
        n.y = -n.y;
    }
    const Vec3 pn = si.to_world(n / std::sqrt(len2));
    Vec3 s = tangent - pn * dot(pn, tangent);
    const float s2 = squared_norm(s);
    if (!(s2 > 0)) return Frame(pn);
    s = s / std::sqrt(s2);
    return Frame(s, cross(pn, s), pn);
}

SurfaceInteraction PerturbedFrameBSDF::perturbed(const SurfaceInteraction &si, const Vec3 &wi, Vec3 &wi_p) const {
    SurfaceInteraction p = si;
    p.sh_frame = perturbed_frame(si, wi);
    wi_p = p.to_local(si.to_world(wi));
    p.wi = wi_p;
    return p;
}

float PerturbedFrameBSDF::shadowing(const Vec3 &np, const Vec3 &wo) const {
    if (!shadowing_) return 1.f;
    auto tan2 = [](const Vec3 &v) {
        const float c2 = v.z * v.z;
        return c2 > 0 ? std::max(0.f, 1.f - c2) / c2 : kInfinity;
    };
    const float alpha2 = std::min(0.125f * tan2(np), 1.f);
    return 2.f / (1.f + std::sqrt(1.f + alpha2 * tan2(wo)));
}

namespace {

// Importance transport corrects for shading normals (Veach's thesis §5.3) with the frame of the hit,
// si.sh_frame (the integrator does: path_vertex.cpp); a bump or normal map's BSDF has the perturbed normal
// as its shading normal, so the rest of the correction, from one normal to the other, is applied here:
// |wi·nb| |wo·ns| / (|wo·nb| |wi·ns|), with ns = z of si's frame and nb = z of the perturbed one. Without it
// light tracing and BDPT render a bump-mapped surface brighter or darker than path tracing does.
float importance_correction(const BSDFContext &ctx, const Vec3 &wi, const Vec3 &wo, const Vec3 &wi_p, const Vec3 &wo_p) {
    if (ctx.mode != TransportMode::Importance) return 1.f;
    const float den = std::abs(wo_p.z * wi.z);
    return den > 0 ? std::abs(wi_p.z * wo.z) / den : 0.f;
}

// The direction toward the light must lie on the same side of both frames (Mitsuba's rule for wo in
// radiance mode): else the perturbed BSDF would take light from behind the surface.
bool same_side(const Vec3 &w, const Vec3 &w_p) { return w.z * w_p.z > 0.f; }

}  // namespace

// Which of wi and wo is which side of the path: the flip of invalid normals is decided by the direction
// toward the camera and the shadowing term reads the direction toward the light, in either transport mode,
// so that light tracing and BDPT shade a perturbed frame as path tracing does (Mitsuba 3 reads wi and wo as they
// come, which matches in radiance mode). Sampling starts from wi, so the frame it samples with is flipped
// by wi; in importance mode eval's frame may differ, and the sample's weight is then eval / pdf.
namespace {
const Vec3 &camera_side(const BSDFContext &ctx, const Vec3 &wi, const Vec3 &wo) {
    return ctx.mode == TransportMode::Radiance ? wi : wo;
}
const Vec3 &light_side(const BSDFContext &ctx, const Vec3 &wi, const Vec3 &wo) {
    return ctx.mode == TransportMode::Radiance ? wo : wi;
}
}  // namespace

Color PerturbedFrameBSDF::eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    SurfaceInteraction p = si;
    p.sh_frame = perturbed_frame(si, camera_side(ctx, wi, wo));
    const Vec3 wi_p = p.to_local(si.to_world(wi)), wo_p = p.to_local(si.to_world(wo));
    p.wi = wi_p;
    if (!same_side(light_side(ctx, wi, wo), light_side(ctx, wi_p, wo_p))) return Color(0.f);
    return nested_->eval(ctx, p, wi_p, wo_p) *
           (importance_correction(ctx, wi, wo, wi_p, wo_p) * shadowing(si.to_local(p.sh_frame.n), light_side(ctx, wi, wo)));
}

float PerturbedFrameBSDF::pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    Vec3 wi_p;
    SurfaceInteraction p = perturbed(si, wi, wi_p);  // the frame sample() draws with
    const Vec3 wo_p = p.to_local(si.to_world(wo));
    return same_side(light_side(ctx, wi, wo), light_side(ctx, wi_p, wo_p)) ? nested_->pdf(ctx, p, wi_p, wo_p) : 0.f;
}

BSDFEval PerturbedFrameBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
                               const Vec3 &wo) const {
    if (ctx.mode == TransportMode::Importance) return {eval(ctx, si, wi, wo), pdf(ctx, si, wi, wo)};
    Vec3 wi_p;
    SurfaceInteraction p = perturbed(si, wi, wi_p);  // once for both (a texture gradient lookup)
    const Vec3 wo_p = p.to_local(si.to_world(wo));
    if (!same_side(wo, wo_p)) return {};
    BSDFEval e = nested_->eval_pdf(ctx, p, wi_p, wo_p);
    e.f *= shadowing(si.to_local(p.sh_frame.n), wo);
    return e;
}

BSDFSample PerturbedFrameBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                               Vec2 u2) const {
    Vec3 wi_p;
    SurfaceInteraction p = perturbed(si, wi, wi_p);
    if (ctx.mode == TransportMode::Importance && !same_side(wi, wi_p)) return {};
    BSDFSample bs = nested_->sample(ctx, p, wi_p, u1, u2);
    const Vec3 wo_p = bs.wo;
    bs.wo = si.to_local(p.to_world(bs.wo));
    if (!bs.valid() || (ctx.mode == TransportMode::Radiance && !same_side(bs.wo, wo_p))) return {};
    if (ctx.mode == TransportMode::Importance && !(bs.sampled_flags & BSDFDelta)) {
        bs.weight = eval(ctx, si, wi, bs.wo) / bs.pdf;  // eval's frame is flipped by the camera side, bs.wo
        return bs;
    }
    bs.weight *= importance_correction(ctx, wi, bs.wo, wi_p, wo_p) * shadowing(si.to_local(p.sh_frame.n), light_side(ctx, wi, bs.wo));
    return bs;
}

}  // namespace neepp
