// A BSDF: Oren and Nayar's rough diffuse reflection (the qualitative model, SIGGRAPH 1994), a Lambertian
// surface made of V-shaped facets whose slopes have a standard deviation sigma. It brightens toward the
// light and looks flatter than Lambertian; at sigma = 0 it is Lambertian.
#include <algorithm>
#include <cmath>
#include "neepp/loader/plugins.h"
#include "neepp/math/warp.h"

namespace example {
using namespace neepp;

class OrenNayarBSDF final : public BSDF {
public:
    OrenNayarBSDF(TexturePtr reflectance, float sigma_degrees) : reflectance_(std::move(reflectance)) {
        const float s2 = std::pow(sigma_degrees * kPi / 180.f, 2.f);
        a_ = 1.f - s2 / (2.f * (s2 + 0.33f));
        b_ = 0.45f * s2 / (s2 + 0.09f);
    }

    // f(wi, wo) |cos θo|, directions in the shading frame (z is the normal); one-sided, like `diffuse`.
    Color eval(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, const Vec3 &wo) const override {
        if (cos_theta(wi) <= 0 || cos_theta(wo) <= 0) return Color(0.f);
        return reflectance_->eval(si) * (kInvPi * facets(wi, wo) * cos_theta(wo));
    }
    // Sampled by the cosine, as a Lambertian surface: the density of wo whatever wi.
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &wi, const Vec3 &wo) const override {
        if (cos_theta(wi) <= 0 || cos_theta(wo) <= 0) return 0.f;
        return square_to_cosine_hemisphere_pdf(wo);
    }
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi, float, Vec2 u) const override {
        BSDFSample bs;
        if (cos_theta(wi) <= 0) return bs;
        bs.wo = square_to_cosine_hemisphere(u);
        bs.pdf = square_to_cosine_hemisphere_pdf(bs.wo);
        if (!(bs.pdf > 0)) return bs;
        bs.sampled_flags = BSDFDiffuseReflection;
        bs.weight = reflectance_->eval(si) * facets(wi, bs.wo);  // f |cos θo| / pdf: the cosine and 1/π cancel
        return bs;
    }
    uint32_t flags() const override { return BSDFDiffuseReflection; }
    // Its value reads only the azimuths' difference, not which way the tangent points: hits on its shapes
    // may get the cheaper frame built from the normal alone.
    bool needs_tangents() const override { return false; }

private:
    // A + B max(0, cos(φi - φo)) sin α tan β, with α the larger of θi, θo and β the smaller.
    float facets(const Vec3 &wi, const Vec3 &wo) const {
        const float sin_i = std::sqrt(std::max(0.f, 1.f - wi.z * wi.z));
        const float sin_o = std::sqrt(std::max(0.f, 1.f - wo.z * wo.z));
        float cos_dphi = 0.f;
        if (sin_i > 1e-4f && sin_o > 1e-4f) cos_dphi = std::max(0.f, (wi.x * wo.x + wi.y * wo.y) / (sin_i * sin_o));
        const bool i_larger = wi.z < wo.z;  // θi > θo
        const float sin_alpha = i_larger ? sin_i : sin_o;
        const float tan_beta = i_larger ? sin_o / wo.z : sin_i / wi.z;
        return a_ + b_ * cos_dphi * sin_alpha * tan_beta;
    }

    TexturePtr reflectance_;
    float a_ = 1.f, b_ = 0.f;
};

// <bsdf type="orennayar"><rgb name="reflectance" value="0.8"/><float name="sigma" value="30"/></bsdf>
void register_orennayar() {
    register_bsdf("orennayar", [](const PluginProperties &props) -> BSDFPtr {
        const float sigma = props.node.get_float("sigma", 20.f);  // degrees
        if (!(sigma >= 0.f && sigma <= 90.f)) throw props.error("sigma must be in [0, 90] degrees");
        return std::make_shared<OrenNayarBSDF>(props.texture("reflectance", Color(0.5f)), sigma);
    });
}

}  // namespace example
