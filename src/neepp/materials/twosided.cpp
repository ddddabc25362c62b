#include "neepp/materials/twosided.h"

#include <cmath>

namespace neepp {
namespace {
Vec3 flip_z(Vec3 v) { return {v.x, v.y, -v.z}; }
}  // namespace

Color TwoSidedBSDF::eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    return wi.z >= 0 ? front_->eval(ctx, si, wi, wo) : back_->eval(ctx, si, flip_z(wi), flip_z(wo));
}

float TwoSidedBSDF::pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    return wi.z >= 0 ? front_->pdf(ctx, si, wi, wo) : back_->pdf(ctx, si, flip_z(wi), flip_z(wo));
}

BSDFEval TwoSidedBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
                                const Vec3 &wo) const {
    return wi.z >= 0 ? front_->eval_pdf(ctx, si, wi, wo) : back_->eval_pdf(ctx, si, flip_z(wi), flip_z(wo));
}

BSDFSample TwoSidedBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                                Vec2 u2) const {
    if (wi.z >= 0) return front_->sample(ctx, si, wi, u1, u2);
    BSDFSample bs = back_->sample(ctx, si, flip_z(wi), u1, u2);
    bs.wo = flip_z(bs.wo);
    return bs;
}

Color MaskBSDF::eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    return nested_->eval(ctx, si, wi, wo) * opacity(si);
}

float MaskBSDF::pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    return nested_->pdf(ctx, si, wi, wo) * opacity(si);
}

BSDFEval MaskBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    BSDFEval e = nested_->eval_pdf(ctx, si, wi, wo);
    const float a = opacity(si);
    return {e.f * a, e.pdf * a};
}

BSDFSample MaskBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                            Vec2 u2) const {
    float a = opacity(si);
    if (u1 >= a) {  // pass through: a null event chosen with probability 1 - a, weight (1-a)/(1-a)
        BSDFSample bs;
        bs.wo = -wi;
        bs.pdf = 1.f - a;
        bs.sampled_flags = BSDFNull;
        bs.weight = Color(1.f);
        return bs;
    }
    BSDFSample bs = nested_->sample(ctx, si, wi, u1 / a, u2);
    bs.pdf *= a;  // f is scaled by a too, so the weight f/pdf is unchanged
    return bs;
}

Frame BumpMapBSDF::perturbed_frame(const SurfaceInteraction &si, const Vec3 &wi) const {
    Vec2 g = height_->eval_1_grad(si);
    g = g * scale_;
    const Vec3 &n = si.sh_frame.n;
    Vec3 dpdu = si.dpdu + n * (g.x - dot(n, si.dpdu));
    Vec3 dpdv = si.dpdv + n * (g.y - dot(n, si.dpdv));
    Vec3 pn = cross(dpdu, dpdv);
    float len2 = squared_norm(pn);
    if (!(len2 > 0) || !std::isfinite(len2)) return si.sh_frame;
    pn = pn / std::sqrt(len2);
    if (dot(si.n, pn) < 0) pn = -pn;
    if (flip_invalid_normals_) {
        // A normal that faces away from wi would shade the side wi is not on (black seams): mirror it
        // about the unperturbed normal, as Mitsuba 3 does.
        Vec3 local = si.to_local(pn);
        if (wi.z * dot(wi, local) <= 0.f) {
            local.x = -local.x;
            local.y = -local.y;
            pn = si.to_world(local);
        }
    }
    Vec3 s = dpdu - pn * dot(pn, dpdu);
    float s2 = squared_norm(s);
    if (!(s2 > 0)) return Frame(pn);
    s = s / std::sqrt(s2);
    return Frame(s, cross(pn, s), pn);
}

SurfaceInteraction BumpMapBSDF::perturbed(const SurfaceInteraction &si, const Vec3 &wi, Vec3 &wi_p) const {
    SurfaceInteraction p = si;
    p.sh_frame = perturbed_frame(si, wi);
    wi_p = p.to_local(si.to_world(wi));
    p.wi = wi_p;
    return p;
}

float BumpMapBSDF::shadowing(const Vec3 &np, const Vec3 &wo) const {
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
// si.sh_frame (the integrator does: path_vertex.cpp); a bump map's BSDF has the perturbed normal as its
// shading normal, so the rest of the correction, from one normal to the other, is applied here:
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
// so that light tracing and BDPT shade a bump map as path tracing does (Mitsuba 3 reads wi and wo as they
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

Color BumpMapBSDF::eval(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    SurfaceInteraction p = si;
    p.sh_frame = perturbed_frame(si, camera_side(ctx, wi, wo));
    const Vec3 wi_p = p.to_local(si.to_world(wi)), wo_p = p.to_local(si.to_world(wo));
    p.wi = wi_p;
    if (!same_side(light_side(ctx, wi, wo), light_side(ctx, wi_p, wo_p))) return Color(0.f);
    return nested_->eval(ctx, p, wi_p, wo_p) *
           (importance_correction(ctx, wi, wo, wi_p, wo_p) * shadowing(si.to_local(p.sh_frame.n), light_side(ctx, wi, wo)));
}

float BumpMapBSDF::pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const {
    Vec3 wi_p;
    SurfaceInteraction p = perturbed(si, wi, wi_p);  // the frame sample() draws with
    const Vec3 wo_p = p.to_local(si.to_world(wo));
    return same_side(light_side(ctx, wi, wo), light_side(ctx, wi_p, wo_p)) ? nested_->pdf(ctx, p, wi_p, wo_p) : 0.f;
}

BSDFEval BumpMapBSDF::eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi,
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

BSDFSample BumpMapBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
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
