#include "neepp/materials/roughplastic.h"

#include <map>
#include <memory>
#include <mutex>
#include <tuple>
#include <tbb/parallel_for.h>

#include "neepp/materials/fresnel.h"
#include "neepp/materials/plastic.h"
#include "neepp/math/warp.h"

namespace neepp {

namespace {

struct CoatingTables {
    std::array<float, RoughPlasticBSDF::kTransmittanceRes> external_transmittance;
    float internal_reflectance;
};

CoatingTables compute_coating_tables(MicrofacetType type, float alpha, float eta) {
    constexpr int kRes = RoughPlasticBSDF::kTransmittanceRes;
    // Mitsuba tabulates with visible-normal quadrature whatever sample_visible says.
    // The entries are independent quadratures: computed in parallel, summed in order afterwards, so the
    // tables do not depend on the thread count.
    MicrofacetDistribution visible(type, alpha, true);
    CoatingTables t;
    std::array<float, kRes> weighted_reflectance;
    tbb::parallel_for(0, kRes, [&](int i) {
        float mu = std::max(1e-6f, float(i) / float(kRes - 1));
        Vec3 wi(std::sqrt(1.f - mu * mu), 0.f, mu);
        t.external_transmittance[i] = eval_transmittance(visible, wi, eta);
        weighted_reflectance[i] = eval_reflectance(visible, wi, 1.f / eta) * mu;
    });
    float reflectance_sum = 0.f;
    for (float r : weighted_reflectance) reflectance_sum += r;
    // Cosine-weighted hemispherical average: 2 * mean over mu of R(mu) mu.
    t.internal_reflectance = reflectance_sum / float(kRes) * 2.f;
    return t;
}

// The tables depend only on (distribution, alpha, eta), which a scene's rough plastics often share, and
// each costs as much as loading a large mesh: computed once per process and copied into each BSDF, whose
// lookups then stay local.
const CoatingTables &coating_tables(MicrofacetType type, float alpha, float eta) {
    static std::mutex mutex;
    static std::map<std::tuple<int, float, float>, std::unique_ptr<const CoatingTables>> memo;
    const std::tuple<int, float, float> key{int(type), alpha, eta};
    {
        std::lock_guard<std::mutex> lock(mutex);
        if (auto it = memo.find(key); it != memo.end()) return *it->second;
    }
    // Computed outside the lock: its parallel loop may run other tasks on this thread meanwhile, one of
    // which could be another material asking here. Two threads may both compute a key; one result stays.
    auto tables = std::make_unique<const CoatingTables>(compute_coating_tables(type, alpha, eta));
    std::lock_guard<std::mutex> lock(mutex);
    return *memo.try_emplace(key, std::move(tables)).first->second;
}

}  // namespace

RoughPlasticBSDF::RoughPlasticBSDF(MicrofacetType type, float alpha, float int_ior, float ext_ior,
                                   TexturePtr diffuse_reflectance, TexturePtr specular_reflectance, bool nonlinear,
                                   bool sample_visible)
    : distr_(type, alpha, sample_visible), eta_(int_ior / ext_ior), inv_eta_2_(1.f / (eta_ * eta_)),
      diffuse_reflectance_(std::move(diffuse_reflectance)),
      specular_reflectance_(specular_reflectance ? std::move(specular_reflectance) : constant_texture(1.f)),
      nonlinear_(nonlinear),
      specular_sampling_weight_(specular_sampling_weight(*diffuse_reflectance_, *specular_reflectance_)) {
    const CoatingTables &t = coating_tables(type, alpha, eta_);
    external_transmittance_ = t.external_transmittance;
    internal_reflectance_ = t.internal_reflectance;
}

float RoughPlasticBSDF::external_transmittance(float cos_theta) const {
    float x = cos_theta * float(kTransmittanceRes - 1);
    int index = std::min(int(x), kTransmittanceRes - 2);
    float t = x - float(index);
    return external_transmittance_[index] * (1.f - t) + external_transmittance_[index + 1] * t;
}

float RoughPlasticBSDF::prob_specular(float t_i) const {
    float p_s = (1.f - t_i) * specular_sampling_weight_, p_d = t_i * (1.f - specular_sampling_weight_);
    return p_s / (p_s + p_d);
}

BSDFEval RoughPlasticBSDF::eval_pdf(const BSDFContext &, const SurfaceInteraction &si, const Vec3 &wi,
                                    const Vec3 &wo) const {
    if (wi.z <= 0.f || wo.z <= 0.f) return {};
    Vec3 h = normalize(wo + wi);
    const float d = distr_.eval(h), g1_i = distr_.smith_g1(wi, h);
    float f = fresnel_dielectric(dot(wi, h), eta_).r;
    Color value = specular_reflectance_->eval(si) * (f * d * (g1_i * distr_.smith_g1(wo, h)) / (4.f * wi.z));

    // Diffuse base seen through the coating's transmittance both ways; the internal reflectance is
    // summed as a geometric series (per channel when nonlinear).
    Color diff = diffuse_reflectance_->eval(si);
    diff = diff / (nonlinear_ ? Color(1.f) - diff * internal_reflectance_ : Color(1.f - internal_reflectance_));
    float t_i = external_transmittance(wi.z), t_o = external_transmittance(wo.z);
    BSDFEval r;
    r.f = value + diff * (kInvPi * inv_eta_2_ * wo.z * t_i * t_o);

    // The lobes' mixture density (the specular lobe's probability from the same transmittance t_i).
    float p_spec = prob_specular(t_i);
    const float spec = distr_.reflection_pdf(wi, wo, h, d, g1_i);
    r.pdf = p_spec * spec + (1.f - p_spec) * square_to_cosine_hemisphere_pdf(wo);
    return r;
}

BSDFSample RoughPlasticBSDF::sample(const BSDFContext &ctx, const SurfaceInteraction &si, const Vec3 &wi, float u1,
                                    Vec2 u2) const {
    BSDFSample bs;
    if (wi.z <= 0.f) return bs;
    if (u1 < prob_specular(external_transmittance(wi.z))) {
        bs.wo = reflect(wi, distr_.sample_normal(wi, u2));
        bs.sampled_flags = BSDFGlossyReflection;
    } else {
        bs.wo = square_to_cosine_hemisphere(u2);
        bs.sampled_flags = BSDFDiffuseReflection;
    }
    // Both lobes can produce either direction, so the weight uses the full mixture density.
    const BSDFEval e = eval_pdf(ctx, si, wi, bs.wo);
    bs.pdf = e.pdf;
    if (!(bs.pdf > 0.f)) return BSDFSample{};
    bs.weight = e.f / bs.pdf;
    return bs;
}

}  // namespace neepp
