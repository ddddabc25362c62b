#include <gtest/gtest.h>
#include "chi2.h"

namespace neepp::test {

Chi2Result chi2_test(const BSDF &bsdf, const Vec3 &wi, const Chi2Config &cfg) {
    BSDFContext ctx{cfg.mode};
    SurfaceInteraction si;
    si.wi = wi;
    SphereChi2Config sphere;
    sphere.res = cfg.res;
    sphere.ires = cfg.ires;
    sphere.sample_count = cfg.sample_count;
    sphere.seed = cfg.seed;
    sphere.min_expected = cfg.min_expected;
    auto sample = [&](PCG32 &rng) -> std::optional<Vec3> {
        float u1 = rng.next_float();
        Vec2 u2 = rng.next_2d();
        BSDFSample bs = bsdf.sample(ctx, si, wi, u1, u2);
        if (!bs.valid() || (bs.sampled_flags & BSDFDelta)) return std::nullopt;
        return bs.wo;
    };
    auto pdf = [&](const Vec3 &wo) { return double(bsdf.pdf(ctx, si, wi, wo)); };
    return chi2_sphere_test(sample, pdf, sphere);
}

void expect_sampling_matches_pdf(const BSDF &bsdf, const Vec3 &wi, int ires, TransportMode mode, uint64_t seed,
                                 size_t cases, const std::string &what) {
    Chi2Config cfg;
    cfg.sample_count = 400000;
    cfg.ires = ires;
    cfg.mode = mode;
    cfg.seed = seed;
    const Chi2Result r = chi2_test(bsdf, wi, cfg);
    SCOPED_TRACE(what + ": " + r.describe());
    ASSERT_TRUE(r.error.empty());
    EXPECT_GT(r.p_value, 0.01 / double(cases));
    EXPECT_LE(r.pdf_integral, 1.0 + 2e-3);
    EXPECT_NEAR(r.pdf_integral, r.valid_fraction, 0.01);
}

}  // namespace neepp::test
