// Phase functions: chi-square of each sampler against its density, densities that integrate to 1, the
// sample's pdf and weight agreeing with eval, and Henyey-Greenstein's mean cosine, which fixes its sign
// convention (g > 0 scatters forward, along the direction light travelled: -wi).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include "common/chi2.h"
#include "neepp/math/warp.h"
#include "neepp/media/phase_functions.h"

using namespace neepp;
using namespace neepp::test;

namespace {

std::vector<std::pair<std::string, std::shared_ptr<PhaseFunction>>> phases() {
    std::vector<std::pair<std::string, std::shared_ptr<PhaseFunction>>> p = {{"isotropic", std::make_shared<IsotropicPhase>()}};
    for (float g : {-0.9f, -0.3f, 0.f, 0.0005f, 0.3f, 0.8f, 0.95f})
        p.push_back({"hg " + std::to_string(g), std::make_shared<HenyeyGreensteinPhase>(g)});
    return p;
}

const Vec3 kWi = normalize(Vec3(0.3f, -0.5f, 0.8f));

}  // namespace

TEST(PhaseFunctions, SamplingMatchesPdf) {
    for (const auto &entry : phases()) {
        // (clang 14 cannot capture a structured binding in the lambdas below)
        const std::string &name = entry.first;
        const PhaseFunction *phase = entry.second.get();
        SphereChi2Config cfg;
        cfg.sample_count = 400000;
        cfg.res = 100;
        cfg.ires = 16;
        cfg.frame = Frame(-kWi);
        const Chi2Result r = chi2_sphere_test(
            [&](PCG32 &rng) -> std::optional<Vec3> {
                const PhaseSample s = phase->sample(kWi, Vec2(rng.next_float(), rng.next_float()));
                if (!(s.pdf > 0)) return std::nullopt;
                return s.wo;
            },
            [&](const Vec3 &wo) { return double(phase->pdf(kWi, wo)); }, cfg);
        EXPECT_TRUE(r.error.empty()) << name << ": " << r.describe();
        EXPECT_GT(r.p_value, 1e-3) << name << ": " << r.describe();
        EXPECT_NEAR(r.pdf_integral, 1.0, 2e-2) << name;  // the harness's quadrature, coarse on peaked lobes
    }
}

TEST(PhaseFunctions, SamplesAgreeWithEvalAndMeanCosineIsG) {
    for (const auto &[name, phase] : phases()) {
        PCG32 rng(3, 7);
        double mean_cos = 0;
        const int n = 200000;
        for (int i = 0; i < n; ++i) {
            const PhaseSample s = phase->sample(kWi, Vec2(rng.next_float(), rng.next_float()));
            ASSERT_GT(s.pdf, 0.f) << name;
            EXPECT_NEAR(norm(s.wo), 1.f, 1e-4f) << name;
            EXPECT_NEAR(s.pdf, phase->pdf(kWi, s.wo), 2e-3f * s.pdf) << name;
            EXPECT_NEAR(s.weight, phase->eval(kWi, s.wo) / s.pdf, 1e-3f) << name;
            mean_cos += dot(-kWi, s.wo);
        }
        mean_cos /= n;
        const auto *hg = dynamic_cast<const HenyeyGreensteinPhase *>(phase.get());
        EXPECT_NEAR(mean_cos, hg ? hg->g() : 0.f, 0.01) << name;
    }
}

// Both are symmetric about the direction of travel: one integral over its cosine, finely.
TEST(PhaseFunctions, DensitiesIntegrateToOne) {
    for (const auto &[name, phase] : phases()) {
        const Frame f(-kWi);
        const int n = 200000;
        double sum = 0;
        for (int i = 0; i < n; ++i) {
            const float c = -1.f + 2.f * (float(i) + 0.5f) / float(n), s = std::sqrt(std::max(0.f, 1.f - c * c));
            sum += phase->eval(kWi, f.to_world(Vec3(s, 0.f, c))) * (2.0 / n) * 2.0 * kPi;
        }
        EXPECT_NEAR(sum, 1.0, 1e-3) << name;
    }
}

TEST(PhaseFunctions, HenyeyGreensteinRefusesGOutsideMinusOneToOne) {
    for (float g : {-1.f, 1.f, 1.5f, std::nanf("")}) EXPECT_THROW(HenyeyGreensteinPhase{g}, std::invalid_argument) << g;
}
