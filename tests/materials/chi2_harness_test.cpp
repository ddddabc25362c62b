// The chi-square harness itself: its p-values and its power to reject a sampler that disagrees with pdf().
#include <gtest/gtest.h>

#include "chi2.h"
#include "neepp/materials/diffuse.h"
#include "neepp/math/warp.h"

namespace neepp::test {
namespace {

TEST(Chi2Harness, PValuesMatchTables) {
    // 5% critical values of the chi-square distribution.
    EXPECT_NEAR(chi2_p_value(3.841459, 1), 0.05, 1e-6);
    EXPECT_NEAR(chi2_p_value(18.307038, 10), 0.05, 1e-6);
    EXPECT_NEAR(chi2_p_value(1074.679449, 1000), 0.05, 1e-5);
    // Closed forms: Q(1, x) = exp(-x); the dof=2 tail is exp(-statistic / 2).
    EXPECT_NEAR(regularized_gamma_q(1.0, 3.0), std::exp(-3.0), 1e-12);
    EXPECT_NEAR(chi2_p_value(7.0, 2), std::exp(-3.5), 1e-12);
    EXPECT_NEAR(regularized_gamma_p(2.5, 1.0) + regularized_gamma_q(2.5, 1.0), 1.0, 1e-12);
}

// pdf() claims cosine-weighted, but sample() draws uniformly: the harness must reject it.
class MismatchedBSDF final : public BSDF {
public:
    Color eval(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &wo) const override {
        return Color(wo.z > 0 ? wo.z * kInvPi : 0.f);
    }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &wo) const override {
        return square_to_cosine_hemisphere_pdf(wo);
    }
    BSDFSample sample(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, float, Vec2 u2) const override {
        BSDFSample bs;
        bs.wo = square_to_uniform_hemisphere(u2);
        bs.pdf = square_to_cosine_hemisphere_pdf(bs.wo);
        bs.weight = Color(1.f);
        bs.sampled_flags = BSDFDiffuseReflection;
        return bs;
    }
    uint32_t flags() const override { return BSDFDiffuseReflection; }
};

TEST(Chi2Harness, RejectsMismatchedSamplerAndAcceptsDiffuse) {
    Chi2Config cfg;
    cfg.sample_count = 200000;
    Chi2Result bad = chi2_test(MismatchedBSDF(), Vec3(0, 0, 1), cfg);
    EXPECT_LT(bad.p_value, 1e-6) << bad.describe();

    Chi2Result good = chi2_test(DiffuseBSDF(constant_texture(0.5f)), Vec3(0, 0, 1), cfg);
    EXPECT_TRUE(good.error.empty()) << good.describe();
    EXPECT_GT(good.p_value, 1e-3) << good.describe();
    EXPECT_NEAR(good.pdf_integral, 1.0, 1e-3);
}

}  // namespace
}  // namespace neepp::test
