// Mitsuba's hair BSDF (Chiang et al. 2016): its sampling against its density (chi-square) for pigmented,
// smooth, rough, white and tinted fibres seen along, across and from behind; sample weight = eval / pdf in
// both transport modes; energy (a white fibre conserves it: white furnace 1 from every direction) and
// absorption; the symmetry the model has (a mirror across the plane of the fibre and the normal) and the
// one it lacks (reciprocity), with importance transport as its adjoint. Values against Mitsuba's own:
// mitsuba_reference_test.cpp.
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

#include "chi2.h"
#include "common/bsdf_test_helpers.h"
#include "neepp/materials/hair.h"
#include "neepp/sampling/rng.h"

namespace neepp::test {
namespace {

const BSDFContext kRadiance{TransportMode::Radiance}, kImportance{TransportMode::Importance};

// The direction at longitudinal angle theta from the plane normal to the fibre (which runs along y),
// whose projection on that plane lies gamma from the normal z, toward -x (gamma > 90: behind).
Vec3 fibre(float theta_deg, float gamma_deg) {
    const float t = theta_deg * kPi / 180.f, g = gamma_deg * kPi / 180.f;
    return {-std::sin(g) * std::cos(t), std::sin(t), std::cos(g) * std::cos(t)};
}

struct Set {
    std::string name;
    std::function<void(HairParams &)> set;
};

BSDFPtr make(const Set &s) {
    HairParams p;
    p.sigma_a = constant_texture(hair_pigment_absorption(1.3f, 0.2f));
    s.set(p);
    return std::make_shared<HairBSDF>(p);
}

const std::vector<Set> &parameter_sets() {
    static const std::vector<Set> sets = {
        {"default", [](HairParams &) {}},
        {"blonde_smooth", [](HairParams &p) {
             p.sigma_a = constant_texture(hair_pigment_absorption(0.3f, 0.2f));
             p.longitudinal_roughness = 0.15f, p.azimuthal_roughness = 0.2f, p.scale_tilt_deg = 3.f;
         }},
        // Little absorbed: the longer walks (lobe 3) carry a large share.
        {"white_rough", [](HairParams &p) {
             p.sigma_a = constant_texture(0.f);
             p.longitudinal_roughness = 0.7f, p.azimuthal_roughness = 0.8f, p.scale_tilt_deg = 0.f;
         }},
        {"tinted_tilted", [](HairParams &p) {
             p.sigma_a = constant_texture(Color(0.4f, 0.5f, 1.4f));
             p.longitudinal_roughness = 0.25f, p.azimuthal_roughness = 0.4f, p.scale_tilt_deg = -5.f;
             p.eta = 1.3f;
         }},
        // Lobes a few degrees wide.
        {"very_smooth", [](HairParams &p) {
             p.sigma_a = constant_texture(hair_pigment_absorption(0.5f, 0.3f));
             p.longitudinal_roughness = 0.08f, p.azimuthal_roughness = 0.1f;
         }},
    };
    return sets;
}

const Set &set_named(const std::string &name) {
    for (const Set &s : parameter_sets())
        if (s.name == name) return s;
    throw std::logic_error(name);
}

// Integral over the sphere of g(wo), by the midpoint rule in the longitudinal angle theta (from the plane
// normal to the fibre, y) and the azimuth phi, dw = cos(theta) dtheta dphi: even in angle, so lobes a few
// degrees wide are resolved near the fibre's axis too.
template <class G>
double over_sphere(const G &g, int ntheta = 400, int nphi = 800) {
    double sum = 0;
    for (int i = 0; i < ntheta; ++i) {
        const float theta = kPi * ((i + 0.5f) / ntheta - 0.5f), y = std::sin(theta), r = std::cos(theta);
        double ring = 0;
        for (int j = 0; j < nphi; ++j) {
            const float phi = 2.f * kPi * (j + 0.5f) / nphi;
            ring += g(Vec3(r * std::cos(phi), y, r * std::sin(phi)));
        }
        sum += ring * r;
    }
    return sum * (kPi / ntheta) * (2.0 * kPi / nphi);
}

// ---- chi-square ----

struct Chi2Case {
    std::string set;
    float theta_deg, gamma_deg;
    int ires = 4;
    TransportMode mode = TransportMode::Radiance;
};

const std::vector<Chi2Case> &chi2_cases() {
    static const std::vector<Chi2Case> cases = {
        {"default", 0.f, 0.f, 8},          {"default", 30.f, 40.f, 8},       {"default", -55.f, -65.f, 8},
        {"default", 20.f, 150.f, 8},       {"default", 40.f, 25.f, 8, TransportMode::Importance},
        {"blonde_smooth", 15.f, -30.f, 12}, {"blonde_smooth", 70.f, 60.f, 12},
        {"white_rough", 0.f, 80.f},        {"white_rough", -80.f, 10.f},     {"white_rough", 35.f, 120.f},
        {"tinted_tilted", 45.f, -10.f, 8}, {"tinted_tilted", -20.f, 85.f, 8},
        {"very_smooth", 25.f, 20.f, 16},
    };
    return cases;
}

class HairChi2 : public ::testing::TestWithParam<size_t> {};

TEST_P(HairChi2, SamplingMatchesPdf) {
    const Chi2Case &k = chi2_cases()[GetParam()];
    expect_sampling_matches_pdf(*make(set_named(k.set)), fibre(k.theta_deg, k.gamma_deg), k.ires, k.mode,
                                3000 + GetParam(), chi2_cases().size(),
                                k.set + " theta=" + std::to_string(k.theta_deg) + " gamma=" + std::to_string(k.gamma_deg));
}

INSTANTIATE_TEST_SUITE_P(Sets, HairChi2, ::testing::Range<size_t>(0, chi2_cases().size()),
                         [](const ::testing::TestParamInfo<size_t> &info) {
                             const Chi2Case &k = chi2_cases()[info.param];
                             auto deg = [](float d) { return (d < 0 ? "m" : "") + std::to_string(int(std::abs(d))); };
                             return k.set + "_theta" + deg(k.theta_deg) + "_gamma" + deg(k.gamma_deg) +
                                    (k.mode == TransportMode::Importance ? "_importance" : "");
                         });

// ---- consistency ----

TEST(Hair, SampleWeightIsEvalOverPdfInBothModes) {
    PCG32 rng(5, 3);
    SurfaceInteraction si;
    for (const Set &s : parameter_sets()) {
        const BSDFPtr bsdf = make(s);
        int checked = 0, through = 0;
        for (int i = 0; i < 3000; ++i) {
            const Vec3 wi = random_direction(rng, false);
            si.wi = wi;
            const float u1 = rng.next_float();
            const Vec2 u2 = rng.next_2d();
            for (const BSDFContext &ctx : {kRadiance, kImportance}) {
                const BSDFSample bs = bsdf->sample(ctx, si, wi, u1, u2);
                if (!bs.valid()) continue;
                EXPECT_NEAR(norm(bs.wo), 1.f, 1e-5f);
                const bool transmitted = bs.wo.z * wi.z < 0;
                EXPECT_EQ(bs.sampled_flags, transmitted ? BSDFGlossyTransmission : BSDFGlossyReflection);
                EXPECT_EQ(bs.eta, 1.f);
                const BSDFEval e = bsdf->eval_pdf(ctx, si, wi, bs.wo);
                EXPECT_NEAR(bs.pdf, e.pdf, 1e-5f * e.pdf) << s.name;
                expect_rel(bs.weight * bs.pdf, e.f, 1e-4f, s.name + ": weight * pdf vs eval");
                EXPECT_EQ(e.pdf, bsdf->pdf(ctx, si, wi, bs.wo));
                ++checked;
                through += transmitted;
            }
        }
        // Every sample is valid; TT and the longer walks cross the fibre.
        EXPECT_GT(checked, 5900) << s.name;
        EXPECT_GT(through, 600) << s.name;
    }
}

// ---- energy ----

// Without absorption every walk leaves the fibre: from any direction, grazing along the fibre and from
// behind included, eval integrates to 1 over the sphere (each lobe is normalized and the attenuations
// sum to 1), however narrow the lobes. Every sample then weighs exactly 1. (Mitsuba's, with its
// approximate Bessel function, reflects 0.9956 at beta 0.5 and normal incidence.)
TEST(Hair, WhiteFurnaceIsOne) {
    SurfaceInteraction si;
    PCG32 rng(2, 9);
    double worst = 0;
    for (float beta : {0.1f, 0.3f, 0.5f, 1.f}) {
        HairParams p;
        p.sigma_a = constant_texture(0.f);
        p.longitudinal_roughness = beta, p.azimuthal_roughness = std::min(1.f, beta + 0.1f);
        p.scale_tilt_deg = 3.f;
        const HairBSDF hair(p);
        for (const Vec3 &wi : {fibre(0, 0), fibre(35, 50), fibre(-70, -20), fibre(85, 30), fibre(10, 160)}) {
            si.wi = wi;
            const double albedo = over_sphere([&](const Vec3 &wo) { return double(hair.eval(kRadiance, si, wi, wo).y); });
            EXPECT_NEAR(albedo, 1.0, 1e-3) << "beta " << beta << " wi " << wi.x << "," << wi.y << "," << wi.z;
            worst = std::max(worst, std::abs(albedo - 1.0));
            for (int i = 0; i < 200; ++i) {
                const BSDFSample bs = hair.sample(kRadiance, si, wi, rng.next_float(), rng.next_2d());
                ASSERT_TRUE(bs.valid());
                expect_rel(bs.weight, Color(1.f), 1e-5f, "white weight");
            }
        }
    }
    std::printf("white furnace: largest |albedo - 1| %.2g\n", worst);
}

// Pigments absorb: the albedo (the mean sample weight, and eval integrated, which must agree) falls as
// eumelanin rises, and brown hair keeps more red than green than blue.
TEST(Hair, PigmentsAbsorbAndColour) {
    SurfaceInteraction si;
    const Vec3 wi = fibre(20, 30);
    si.wi = wi;
    double previous = 1.0;
    for (float eumelanin : {0.f, 0.3f, 1.3f, 4.f}) {
        HairParams p;
        p.sigma_a = constant_texture(hair_pigment_absorption(eumelanin, 0.2f));
        const HairBSDF hair(p);
        PCG32 rng(4, 1);
        Color mean_weight(0.f);
        const int n = 100000;
        for (int i = 0; i < n; ++i) mean_weight += hair.sample(kRadiance, si, wi, rng.next_float(), rng.next_2d()).weight;
        mean_weight /= float(n);
        Color integral;
        for (int c = 0; c < 3; ++c)
            integral[c] = float(over_sphere([&](const Vec3 &wo) { return double(hair.eval(kRadiance, si, wi, wo)[c]); }, 200, 400));
        std::printf("eumelanin %.1f: albedo %.4f %.4f %.4f (sampled %.4f %.4f %.4f)\n", eumelanin, integral.x,
                    integral.y, integral.z, mean_weight.x, mean_weight.y, mean_weight.z);
        expect_rel(mean_weight, integral, 0.02f, "sampled albedo vs integrated");
        EXPECT_LT(integral.x, previous);
        EXPECT_GT(integral.x, integral.y);
        EXPECT_GT(integral.y, integral.z);
        previous = integral.x;
    }
}

// sigma_a times scale; a negative absorption (gain, whose longer walks would diverge) counts as 0.
TEST(Hair, AbsorptionTextureScaleAndClamp) {
    auto hair = [](Color sigma_a, float scale) {
        HairParams p;
        p.sigma_a = constant_texture(sigma_a);
        p.sigma_a_scale = scale;
        return HairBSDF(p);
    };
    SurfaceInteraction si;
    PCG32 rng(8, 8);
    const HairBSDF scaled = hair(Color(0.1f, 0.2f, 0.3f), 4.f), plain = hair(Color(0.4f, 0.8f, 1.2f), 1.f);
    const HairBSDF negative = hair(Color(-1.f, 0.f, -0.5f), 1.f), white = hair(Color(0.f), 1.f);
    for (int i = 0; i < 200; ++i) {
        const Vec3 wi = random_direction(rng, false), wo = random_direction(rng, false);
        expect_rel(scaled.eval(kRadiance, si, wi, wo), plain.eval(kRadiance, si, wi, wo), 1e-5f, "scale");
        expect_rel(negative.eval(kRadiance, si, wi, wo), white.eval(kRadiance, si, wi, wo), 1e-6f, "clamp");
    }
}

// ---- symmetry ----

// Mirroring both directions across the plane of the fibre and the normal (x -> -x) mirrors the fibre
// onto itself: the offset h and the azimuths change sign together, and nothing else changes.
TEST(Hair, MirrorAcrossTheFibrePlaneChangesNothing) {
    PCG32 rng(6, 2);
    SurfaceInteraction si;
    for (const Set &s : parameter_sets()) {
        const BSDFPtr bsdf = make(s);
        for (int i = 0; i < 500; ++i) {
            const Vec3 wi = random_direction(rng, false), wo = random_direction(rng, false);
            const Vec3 mi(-wi.x, wi.y, wi.z), mo(-wo.x, wo.y, wo.z);
            for (const BSDFContext &ctx : {kRadiance, kImportance}) {
                const BSDFEval a = bsdf->eval_pdf(ctx, si, wi, wo), b = bsdf->eval_pdf(ctx, si, mi, mo);
                expect_rel(a.f, b.f, 1e-3f, s.name + ": mirrored eval");
                EXPECT_NEAR(a.pdf, b.pdf, 1e-3f * a.pdf + 1e-7f) << s.name;
            }
        }
    }
}

// The near-field model is not reciprocal: h follows wi alone and the scales tilt each lobe one way, so
// f(a, b) and f(b, a) differ (by more than a quarter for some pairs off the horizon). Importance transport therefore
// carries its adjoint: f_importance(wi, wo) / |cos wo| == f_radiance(wo, wi) / |cos wi|, at the same
// sampling density.
TEST(Hair, NotReciprocalSoImportanceIsTheAdjoint) {
    PCG32 rng(9, 4);
    SurfaceInteraction si;
    for (const Set &s : parameter_sets()) {
        const BSDFPtr bsdf = make(s);
        double asymmetry = 0;
        for (int i = 0; i < 2000; ++i) {
            const Vec3 a = random_direction(rng, false), b = random_direction(rng, false);
            const Color rad_ab = bsdf->eval(kRadiance, si, a, b), rad_ba = bsdf->eval(kRadiance, si, b, a);
            expect_rel(bsdf->eval(kImportance, si, b, a) / std::abs(a.z), rad_ab / std::abs(b.z), 1e-5f,
                       s.name + ": adjoint");
            EXPECT_EQ(bsdf->pdf(kImportance, si, a, b), bsdf->pdf(kRadiance, si, a, b));
            const float f_ab = luminance(rad_ab) / std::abs(b.z), f_ba = luminance(rad_ba) / std::abs(a.z);
            if (std::min(std::abs(a.z), std::abs(b.z)) > 0.3f && f_ab > 0.05f && f_ba > 0.05f) asymmetry = std::max(asymmetry, double(std::abs(f_ab - f_ba) / f_ab));
        }
        std::printf("%s: largest relative asymmetry f(a,b) vs f(b,a) %.3f\n", s.name.c_str(), asymmetry);
        EXPECT_GT(asymmetry, 0.25) << s.name;
    }
}

TEST(Hair, RejectsParametersWithoutADensity) {
    auto with = [](const std::function<void(HairParams &)> &set) {
        HairParams p;
        set(p);
        return [p] { HairBSDF h(p); };
    };
    EXPECT_THROW(with([](HairParams &p) { p.longitudinal_roughness = 0.f; })(), std::invalid_argument);
    EXPECT_THROW(with([](HairParams &p) { p.azimuthal_roughness = 1.5f; })(), std::invalid_argument);
    EXPECT_THROW(with([](HairParams &p) { p.eta = 1.f; })(), std::invalid_argument);
    EXPECT_THROW(with([](HairParams &p) { p.scale_tilt_deg = NAN; })(), std::invalid_argument);
    EXPECT_THROW(with([](HairParams &p) { p.sigma_a_scale = -1.f; })(), std::invalid_argument);
    EXPECT_NO_THROW(with([](HairParams &p) { p.longitudinal_roughness = 1.f, p.azimuthal_roughness = 1e-3f; })());
}

}  // namespace
}  // namespace neepp::test
