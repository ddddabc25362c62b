// Phase functions: chi-square of each sampler against its density, densities that integrate to 1, the
// sample's pdf and weight agreeing with eval, and each one's mean cosine to the direction light travelled
// (-wi), which fixes the sign conventions: g > 0 scatters forward in Henyey-Greenstein, a tabphase's last
// value is the forward one, a blend's weight is the second phase function's share.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include "common/chi2.h"
#include "neepp/math/warp.h"
#include "neepp/media/blend_phase.h"
#include "neepp/media/phase_functions.h"
#include "neepp/media/tabulated_phase.h"

using namespace neepp;
using namespace neepp::test;

namespace {

struct PhaseCase {
    std::string name;
    std::shared_ptr<const PhaseFunction> phase;
    double mean_cos;             // E[dot(-wi, wo)], known in closed form
    Vec3 p = Vec3(0.2f, 0.4f, 0.6f);  // where it is evaluated (a blend's weight volume varies)
    int ires = 8;                // the chi-square's Simpson subintervals per bin (SamplingMatchesPdf)
};

std::shared_ptr<const Volume> constant(float w) { return std::make_shared<ConstantVolume>(Color(w)); }

// A weight that rises from 0 to 1 along x through the unit cube: 0 up to the first texel centre (x = 0.25),
// 1 from the second (x = 0.75), linear between.
std::shared_ptr<const Volume> ramp_x() {
    VolumeGrid g;
    g.size[0] = 2, g.size[1] = 1, g.size[2] = 1, g.channels = 1;
    g.values = {0.f, 1.f};
    return std::make_shared<GridVolume>(g, GridVolumeOptions{});
}

std::vector<PhaseCase> phases() {
    std::vector<PhaseCase> p = {{"isotropic", std::make_shared<IsotropicPhase>(), 0.0}};
    // The lobes sharper than the chi-square's bins need its quadrature fine (SamplingMatchesPdf).
    for (float g : {-0.9f, -0.3f, 0.f, 0.0005f, 0.3f, 0.8f, 0.95f})
        p.push_back({"hg " + std::to_string(g), std::make_shared<HenyeyGreensteinPhase>(g), g, Vec3(0.2f, 0.4f, 0.6f),
                     std::abs(g) > 0.85f ? 16 : 8});
    p.push_back({"rayleigh", std::make_shared<RayleighPhase>(), 0.0});
    // Tables over cos_theta in [-1, 1]. Flat is isotropic; a density rising linearly to the forward end,
    // (1 + c) / 2, has mean cosine 1/3; (2 - c) / 4 (3 at -1, 1 at 1, normalised) has -1/6.
    const auto tab = [](std::vector<float> v) { return std::make_shared<TabulatedPhase>(std::move(v)); };
    p.push_back({"tabphase flat", tab({1, 1}), 0.0});
    p.push_back({"tabphase forward ramp", tab({0, 1}), 1.0 / 3.0});
    p.push_back({"tabphase backward", tab({3, 2, 1}), -1.0 / 6.0});
    // A hole with no density (cos in (-1/3, 1/3)): nothing may be sampled there. These two have their mean
    // from quadrature.
    p.push_back({"tabphase hole", tab({1, 0, 0, 2}), NAN});
    p.push_back({"tabphase peaked", tab({0.1f, 0.1f, 0.2f, 0.5f, 1.f, 3.f, 12.f}), NAN});
    const auto hg_fwd = std::make_shared<HenyeyGreensteinPhase>(0.8f);
    const auto hg_back = std::make_shared<HenyeyGreensteinPhase>(-0.5f);
    for (float w : {0.f, 0.3f, 1.f})
        p.push_back({"blend hg 0.8 / hg -0.5, w " + std::to_string(w), std::make_shared<BlendPhase>(hg_fwd, hg_back, constant(w)),
                     (1.0 - w) * 0.8 + w * -0.5});
    // Weights outside [0, 1] are clipped: the first alone, the second alone.
    p.push_back({"blend w -0.4", std::make_shared<BlendPhase>(hg_fwd, hg_back, constant(-0.4f)), 0.8});
    p.push_back({"blend w 1.7", std::make_shared<BlendPhase>(hg_fwd, hg_back, constant(1.7f)), -0.5});
    // A weight read from a volume at the point: 0.5 halfway along the ramp, 0 before it, 1 after it.
    const auto ramped = std::make_shared<BlendPhase>(hg_fwd, hg_back, ramp_x());
    p.push_back({"blend ramp x=0.5", ramped, 0.5 * 0.8 + 0.5 * -0.5, Vec3(0.5f, 0.5f, 0.5f)});
    p.push_back({"blend ramp x=0.1", ramped, 0.8, Vec3(0.1f, 0.5f, 0.5f)});
    p.push_back({"blend ramp x=0.9", ramped, -0.5, Vec3(0.9f, 0.5f, 0.5f)});
    // Nested blends and lobes of other kinds; a colour weight counts by its luminance.
    const auto tab_fwd = tab({0, 1});
    p.push_back({"blend rayleigh / tabphase", std::make_shared<BlendPhase>(std::make_shared<RayleighPhase>(), tab_fwd, constant(0.6f)),
                 0.6 / 3.0});
    const auto inner = std::make_shared<BlendPhase>(hg_fwd, hg_back, constant(0.5f));
    const double lum = luminance(Color(0.2f, 0.9f, 0.1f));
    p.push_back({"blend of a blend, colour weight",
                 std::make_shared<BlendPhase>(inner, std::make_shared<IsotropicPhase>(),
                                              std::make_shared<ConstantVolume>(Color(0.2f, 0.9f, 0.1f))),
                 (1.0 - lum) * 0.15});
    return p;
}

const Vec3 kWi = normalize(Vec3(0.3f, -0.5f, 0.8f));

// The integral of the phase function's value over the sphere, and of its value times the cosine to the
// direction of travel, by the midpoint rule over that cosine (each of these is symmetric about -wi).
std::pair<double, double> integrate(const PhaseFunction &phase, const Vec3 &p) {
    const Frame f(-kWi);
    const int n = 200000;
    double sum = 0, mean = 0;
    for (int i = 0; i < n; ++i) {
        const double c = -1.0 + 2.0 * (double(i) + 0.5) / double(n), s = std::sqrt(std::max(0.0, 1.0 - c * c));
        const double v = phase.eval(p, kWi, f.to_world(Vec3(float(s), 0.f, float(c)))) * (2.0 / n) * 2.0 * kPi;
        sum += v;
        mean += v * c;
    }
    return {sum, mean};
}

}  // namespace

TEST(PhaseFunctions, SamplingMatchesPdf) {
    for (const PhaseCase &c : phases()) {
        const PhaseFunction *phase = c.phase.get();
        const Vec3 p = c.p;
        SphereChi2Config cfg;
        cfg.sample_count = 400000;
        cfg.res = 100;
        // Simpson's rule with 8 subintervals per bin gives every expected count of these densities within
        // 1.4e-5 of its value (relative; against 32 subintervals): the statistic of a right sampler moves by
        // 2e-5 at most where it spreads by 125 or more (sqrt(2 dof)), one of a slightly wrong sampler (hg 0.8
        // sampled, 0.79 claimed) by 0.14 of its excess of 540, and the pdf integral by 2e-6. Only the two
        // sharpest lobes (hg 0.95, hg -0.9: a peak narrower than a bin) need 16, which all of them took.
        cfg.ires = c.ires;
        cfg.frame = Frame(-kWi);
        const Chi2Result r = chi2_sphere_test(
            [&](PCG32 &rng) -> std::optional<Vec3> {
                const PhaseSample s = phase->sample(p, kWi, Vec2(rng.next_float(), rng.next_float()));
                if (!(s.pdf > 0)) return std::nullopt;
                return s.wo;
            },
            [&](const Vec3 &wo) { return double(phase->pdf(p, kWi, wo)); }, cfg);
        EXPECT_TRUE(r.error.empty()) << c.name << ": " << r.describe();
        EXPECT_GT(r.p_value, 1e-3) << c.name << ": " << r.describe();
        EXPECT_NEAR(r.pdf_integral, 1.0, 2e-2) << c.name;  // the harness's quadrature, coarse on peaked lobes
        EXPECT_NEAR(r.valid_fraction, 1.0, 1e-6) << c.name;
    }
}

TEST(PhaseFunctions, SamplesAgreeWithEvalAndMeanCosineIsKnown) {
    for (const PhaseCase &c : phases()) {
        PCG32 rng(3, 7);
        double mean_cos = 0;
        const int n = 200000;
        for (int i = 0; i < n; ++i) {
            const PhaseSample s = c.phase->sample(c.p, kWi, Vec2(rng.next_float(), rng.next_float()));
            ASSERT_GT(s.pdf, 0.f) << c.name;
            EXPECT_NEAR(norm(s.wo), 1.f, 1e-4f) << c.name;
            EXPECT_NEAR(s.pdf, c.phase->pdf(c.p, kWi, s.wo), 2e-3f * s.pdf) << c.name;
            // The weight is value over density: exactly 1 for lobes sampled exactly, not for a blend of two.
            EXPECT_NEAR(s.weight, c.phase->eval(c.p, kWi, s.wo) / s.pdf, 1e-3f * s.weight) << c.name;
            mean_cos += dot(-kWi, s.wo);
        }
        mean_cos /= n;
        // Tables without a closed-form mean: the quadrature's (the chi-square test ties it to sampling).
        const double expected = std::isnan(c.mean_cos) ? integrate(*c.phase, c.p).second : c.mean_cos;
        EXPECT_NEAR(mean_cos, expected, 0.01) << c.name;
        EXPECT_NEAR(integrate(*c.phase, c.p).second, expected, 1e-3) << c.name;
    }
}

TEST(PhaseFunctions, DensitiesIntegrateToOne) {
    for (const PhaseCase &c : phases()) EXPECT_NEAR(integrate(*c.phase, c.p).first, 1.0, 1e-3) << c.name;
}

TEST(PhaseFunctions, HenyeyGreensteinRefusesGOutsideMinusOneToOne) {
    for (float g : {-1.f, 1.f, 1.5f, std::nanf("")}) EXPECT_THROW(HenyeyGreensteinPhase{g}, std::invalid_argument) << g;
}

// Mitsuba's values: 3/(16 pi) (1 + cos^2), the same forward and back.
TEST(PhaseFunctions, RayleighValues) {
    const RayleighPhase r;
    const Vec3 p(0.f);
    EXPECT_FLOAT_EQ(r.eval(p, kWi, -kWi), 3.f / (8.f * kPi));
    EXPECT_FLOAT_EQ(r.eval(p, kWi, kWi), 3.f / (8.f * kPi));
    EXPECT_FLOAT_EQ(r.eval(p, kWi, Frame(kWi).s), 3.f / (16.f * kPi));
}

// The table read as Mitsuba reads it: evenly spaced from cos_theta = -1 (backward: wo = wi) to 1 (forward:
// wo = -wi), linear between, normalised by its integral over the cosine, and 1/(2 pi) per unit of azimuth.
TEST(PhaseFunctions, TabulatedValuesAndTheirOrientation) {
    const Vec3 p(0.f);
    // 1 at the back, 3 at the front: mass 4 over the cosine.
    const TabulatedPhase t({1.f, 3.f});
    EXPECT_FLOAT_EQ(t.eval(p, kWi, -kWi), 3.f / 4.f * kInv2Pi);
    EXPECT_FLOAT_EQ(t.eval(p, kWi, kWi), 1.f / 4.f * kInv2Pi);
    EXPECT_FLOAT_EQ(t.eval(p, kWi, Frame(kWi).s), 2.f / 4.f * kInv2Pi);
    // Three points: cos_theta = -1, 0, 1; mass (1 + 2) / 2 + (2 + 0) / 2 = 2.5.
    const TabulatedPhase three({1.f, 2.f, 0.f});
    EXPECT_FLOAT_EQ(three.eval(p, kWi, Frame(kWi).s), 2.f / 2.5f * kInv2Pi);
    EXPECT_NEAR(three.eval(p, kWi, -kWi), 0.f, 1e-6f);  // dot(wi, -wi) rounds near -1
    EXPECT_FLOAT_EQ(TabulatedPhase({5.f, 5.f, 5.f}).eval(p, kWi, Frame(kWi).t), kInv4Pi);
}

TEST(PhaseFunctions, TabulatedRefusesTablesThatAreNotADensity) {
    for (const std::vector<float> &v : std::vector<std::vector<float>>{
             {}, {1.f}, {0.f, 0.f, 0.f}, {1.f, -0.5f}, {1.f, NAN}, {INFINITY, 1.f}})
        EXPECT_THROW(TabulatedPhase{v}, std::invalid_argument) << v.size();
}
