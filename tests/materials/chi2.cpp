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

}  // namespace neepp::test
