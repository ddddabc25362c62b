// The sggx phase function and the microflake media it makes: sampling against the density (chi-square) for
// S of every kind (isotropic, fibre-like, surface-like, rotated), a density that integrates to 1 and
// normals whose projected area is sigma, eval == pdf, reciprocity up to the projected areas, Mitsuba 3's own
// values, S read from a volume at the point, and a medium whose extinction is its density times sigma along
// the ray (a transmittance estimated by delta tracking against its majorant).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include "common/chi2.h"
#include "neepp/base/interaction.h"
#include "neepp/math/warp.h"
#include "neepp/media/free_flight.h"
#include "neepp/media/heterogeneous_medium.h"
#include "neepp/media/homogeneous_medium.h"
#include "neepp/media/phase_functions.h"
#include "neepp/media/sggx_phase.h"
#include "neepp/sampling/sampler.h"

using namespace neepp;
using namespace neepp::test;

namespace {

// R diag(a, b, c) Rᵀ, R the rotation taking x, y, z to the columns u, v, w (orthonormal).
SymmetricMatrix3 oriented(float a, float b, float c, const Vec3 &u, const Vec3 &v, const Vec3 &w) {
    auto outer = [](const Vec3 &x, float k) { return SymmetricMatrix3(k * x.x * x.x, k * x.y * x.y, k * x.z * x.z, k * x.x * x.y, k * x.x * x.z, k * x.y * x.z); };
    return outer(u, a) + outer(v, b) + outer(w, c);
}

struct SggxCase {
    std::string name;
    SymmetricMatrix3 s;
    Vec3 wi;
    // The chi-square test bins about -wi, unless the lobe is a narrow one there (light along a fibre goes
    // on nearly straight): then about this axis, so that it lies across many bins rather than in the
    // polar few.
    Vec3 bin_axis = Vec3(0.f);
};

std::vector<SggxCase> cases() {
    const Vec3 tilted = normalize(Vec3(0.3f, -0.5f, 0.8f));
    const Frame r(normalize(Vec3(0.4f, 0.7f, -0.6f)));  // a rotation with no axis along x, y or z
    return {
        {"isotropic", SymmetricMatrix3(1, 1, 1, 0, 0, 0), tilted},
        {"near isotropic", SymmetricMatrix3(0.9f, 1.f, 0.8f, 0.05f, -0.02f, 0.03f), tilted},
        // Fibres along z: flakes facing every way across z (one small eigenvalue).
        {"fibre", SymmetricMatrix3(1, 1, 0.01f, 0, 0, 0), tilted},
        {"fibre, light along it", SymmetricMatrix3(1, 1, 0.01f, 0, 0, 0), normalize(Vec3(0.05f, 0.02f, 1.f)), Vec3(1, 0, 0)},
        // A surface facing z: flakes near z (two small eigenvalues), a glossy mirror.
        {"surface", SymmetricMatrix3(0.01f, 0.01f, 1, 0, 0, 0), tilted},
        {"surface, grazing", SymmetricMatrix3(0.01f, 0.01f, 1, 0, 0, 0), normalize(Vec3(1.f, 0.3f, 0.08f))},
        // Rotated, all entries off the diagonal, three different eigenvalues.
        {"rotated", oriented(1.f, 0.2f, 0.03f, r.s, r.t, r.n), tilted},
        {"rotated fibre", oriented(1.f, 1.f, 0.01f, r.s, r.t, r.n), normalize(Vec3(-0.7f, 0.1f, 0.2f))},
        // Mitsuba's own chi-square tests' matrices (a largest eigenvalue above 1: projected areas above 1).
        {"mitsuba simple", SymmetricMatrix3(0.15f, 1.f, 0.8f, 0, 0, 0), tilted},
        {"mitsuba skewed", SymmetricMatrix3(1.f, 0.35f, 0.32f, 0.52f, 0.44f, 0.2f), tilted},
    };
}

std::shared_ptr<const SGGXPhase> phase_of(const SymmetricMatrix3 &s) {
    return std::make_shared<SGGXPhase>(std::make_shared<ConstantVolume>(s));
}

// ∫ g(w) dw over the sphere: the midpoint rule over (cos theta, phi) about an axis along none of the test
// matrices' eigenvectors (a lobe at a pole would fall in a few coarse bins), fine enough for lobes a few
// degrees wide.
template <class F> double integrate_sphere(F g, int n_cos = 800, int n_phi = 1600) {
    const Frame f(normalize(Vec3(0.6f, -0.3f, 0.74f)));
    double sum = 0;
    for (int i = 0; i < n_cos; ++i) {
        const double c = -1.0 + 2.0 * (i + 0.5) / n_cos, s = std::sqrt(std::max(0.0, 1.0 - c * c));
        for (int j = 0; j < n_phi; ++j) {
            const double phi = 2.0 * kPi * (j + 0.5) / n_phi;
            sum += g(f.to_world(Vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c))));
        }
    }
    return sum * (2.0 / n_cos) * (2.0 * kPi / n_phi);
}

const Vec3 kP(0.5f);

}  // namespace

TEST(SGGX, SamplingMatchesPdf) {
    for (const SggxCase &c : cases()) {
        const auto phase = phase_of(c.s);
        SphereChi2Config cfg;
        cfg.sample_count = 300000;
        cfg.res = 80;
        cfg.ires = 8;
        cfg.frame = Frame(c.bin_axis == Vec3(0.f) ? -c.wi : c.bin_axis);
        const Chi2Result r = chi2_sphere_test(
            [&](PCG32 &rng) -> std::optional<Vec3> {
                const PhaseSample s = phase->sample(kP, c.wi, Vec2(rng.next_float(), rng.next_float()));
                if (!(s.pdf > 0)) return std::nullopt;
                return s.wo;
            },
            [&](const Vec3 &wo) { return double(phase->pdf(kP, c.wi, wo)); }, cfg);
        EXPECT_TRUE(r.error.empty()) << c.name << ": " << r.describe();
        EXPECT_GT(r.p_value, 1e-3) << c.name << ": " << r.describe();
        EXPECT_NEAR(r.valid_fraction, 1.0, 1e-6) << c.name;
    }
}

// eval is the density sample() draws with (value = pdf, weight 1, as Mitsuba's), and the sampled
// directions are unit vectors.
TEST(SGGX, SamplesAgreeWithEvalAndPdf) {
    for (const SggxCase &c : cases()) {
        const auto phase = phase_of(c.s);
        PCG32 rng(3, 7);
        for (int i = 0; i < 20000; ++i) {
            const PhaseSample s = phase->sample(kP, c.wi, Vec2(rng.next_float(), rng.next_float()));
            ASSERT_GT(s.pdf, 0.f) << c.name;
            EXPECT_NEAR(norm(s.wo), 1.f, 1e-4f) << c.name;
            EXPECT_EQ(s.weight, 1.f) << c.name;
            EXPECT_NEAR(s.pdf, phase->pdf(kP, c.wi, s.wo), 2e-3f * s.pdf) << c.name;
            EXPECT_EQ(phase->eval(kP, c.wi, s.wo), phase->pdf(kP, c.wi, s.wo)) << c.name;
        }
    }
}

// The phase function integrates to 1 over wo; the flakes facing any w (the normal density over the
// hemisphere about w, times the cosine) have area sigma(w), the definition the extinction is scaled by.
TEST(SGGX, DensityIntegratesToOneAndNormalsProjectToSigma) {
    for (const SggxCase &c : cases()) {
        const auto phase = phase_of(c.s);
        EXPECT_NEAR(integrate_sphere([&](const Vec3 &wo) { return double(phase->eval(kP, c.wi, wo)); }), 1.0, 3e-3) << c.name;
        const Vec3 w = normalize(Vec3(-0.2f, 0.9f, 0.4f));
        const double area = integrate_sphere([&](const Vec3 &m) { return double(sggx_normal_density(c.s, m)) * std::max(0.f, dot(m, w)); });
        EXPECT_NEAR(area, sggx_projected_area(c.s, w), 3e-3 * sggx_projected_area(c.s, w)) << c.name;
    }
}

// S = I is a sphere's normals: isotropic scattering, 1 / (4 pi), whatever the scale of S.
TEST(SGGX, IdentityIsIsotropicAndScaleDoesNotMatter) {
    PCG32 rng(1, 2);
    const auto iso = phase_of(SymmetricMatrix3(1, 1, 1, 0, 0, 0)), big = phase_of(SymmetricMatrix3(4, 4, 4, 0, 0, 0));
    const SymmetricMatrix3 s(1.f, 0.35f, 0.32f, 0.52f, 0.44f, 0.2f);
    const auto skewed = phase_of(s), skewed_scaled = phase_of(s * 9.f);
    for (int i = 0; i < 1000; ++i) {
        const Vec3 wi = square_to_uniform_sphere(rng.next_2d()), wo = square_to_uniform_sphere(rng.next_2d());
        EXPECT_NEAR(iso->eval(kP, wi, wo), kInv4Pi, 1e-5f);
        EXPECT_NEAR(big->eval(kP, wi, wo), kInv4Pi, 1e-5f);
        const float f = skewed->eval(kP, wi, wo);
        EXPECT_NEAR(skewed_scaled->eval(kP, wi, wo), f, 1e-4f * f);
        EXPECT_NEAR(skewed_scaled->projected_area(kP, wi), 3.f * skewed->projected_area(kP, wi), 1e-5f);
    }
}

// Microflakes are reciprocal in f sigma (D(h) / 4 is symmetric), not in f alone where sigma(wi) differs
// from sigma(wo); where the two are equal (the light's path mirrored by S's symmetry), f is.
TEST(SGGX, ReciprocalUpToTheProjectedAreas) {
    PCG32 rng(5, 9);
    for (const SggxCase &c : cases()) {
        const auto phase = phase_of(c.s);
        bool asymmetric = false;
        for (int i = 0; i < 1000; ++i) {
            const Vec3 wi = square_to_uniform_sphere(rng.next_2d()), wo = square_to_uniform_sphere(rng.next_2d());
            const float a = phase->eval(kP, wi, wo) * phase->projected_area(kP, wi);
            const float b = phase->eval(kP, wo, wi) * phase->projected_area(kP, wo);
            EXPECT_NEAR(a, b, 1e-4f * std::max(a, b) + 1e-12f) << c.name;
            asymmetric |= std::abs(phase->eval(kP, wi, wo) - phase->eval(kP, wo, wi)) > 1e-3f * phase->eval(kP, wi, wo);
        }
        EXPECT_EQ(asymmetric, c.name != "isotropic") << c.name;  // f itself is symmetric only for S = I
    }
    // A diagonal S: sigma is the same for w and its mirror image in a coordinate plane.
    const auto fibre = phase_of(SymmetricMatrix3(1, 1, 0.01f, 0, 0, 0));
    const Vec3 wi = normalize(Vec3(0.3f, -0.5f, 0.8f)), wo = Vec3(wi.x, wi.y, -wi.z);
    EXPECT_FLOAT_EQ(fibre->eval(kP, wi, wo), fibre->eval(kP, wo, wi));
}

// Mitsuba 3.9.1 (scalar_rgb), its sggx phase function over a 1x1x1 gridvolume S, eval_pdf and projected_area
// at wi = (0.3, -0.5, 0.8) / |.|, wo = (-0.6, 0.2, 0.3) / |.| (mi.wi as neepp's wi: toward where light came
// from), and with the two swapped.
TEST(SGGX, MitsubasValues) {
    const Vec3 wi = normalize(Vec3(0.3f, -0.5f, 0.8f)), wo = normalize(Vec3(-0.6f, 0.2f, 0.3f));
    struct Expected {
        SymmetricMatrix3 s;
        float f, f_swapped, area;
    };
    for (const Expected &e : {Expected{{1, 1, 1, 0, 0, 0}, 0.0795774907f, 0.0795774907f, 1.f},
                              Expected{{0.15f, 1.f, 0.8f, 0, 0, 0}, 0.0571299382f, 0.0873143449f, 0.889565349f},
                              Expected{{1.f, 0.35f, 0.32f, 0.52f, 0.44f, 0.2f}, 0.0139503926f, 0.0137127861f, 0.532130837f},
                              Expected{{1, 1, 0.01f, 0, 0, 0}, 0.000202287294f, 0.000132961082f, 0.594532907f},
                              Expected{{0.0004f, 0.0004f, 1, 0, 0, 0}, 0.00110520329f, 0.00208236254f, 0.80820787f}}) {
        const auto phase = phase_of(e.s);
        EXPECT_NEAR(phase->eval(kP, wi, wo), e.f, 2e-5f * e.f) << e.s.xx;
        EXPECT_NEAR(phase->pdf(kP, wi, wo), e.f, 2e-5f * e.f) << e.s.xx;
        EXPECT_NEAR(phase->eval(kP, wo, wi), e.f_swapped, 2e-5f * e.f_swapped) << e.s.xx;
        EXPECT_NEAR(phase->projected_area(kP, wi), e.area, 1e-6f) << e.s.xx;
    }
}

// S from a grid, read at the scattering point: a fibre at one end, a surface at the other, trilinear between
// (each entry interpolated, as Mitsuba interpolates a 6-channel grid).
TEST(SGGX, ReadsSFromAVolumeAtThePoint) {
    const SymmetricMatrix3 fibre(1, 1, 0.01f, 0, 0, 0), surface(0.01f, 0.01f, 1, 0.f, 0.f, 0.f);
    VolumeGrid g;
    g.size[0] = 2, g.size[1] = 1, g.size[2] = 1, g.channels = 6;
    for (const SymmetricMatrix3 &s : {fibre, surface})
        for (float v : s.channels()) g.values.push_back(v);
    const SGGXPhase graded(std::make_shared<GridVolume>(g, GridVolumeOptions{}));
    EXPECT_FLOAT_EQ(graded.max_projected_area(), 1.f);
    const Vec3 wi = normalize(Vec3(0.3f, -0.5f, 0.8f)), wo = normalize(Vec3(-0.6f, 0.2f, 0.3f));
    const auto at = [&](const SymmetricMatrix3 &s) { return phase_of(s)->eval(kP, wi, wo); };
    EXPECT_FLOAT_EQ(graded.eval(Vec3(0.1f, 0.5f, 0.5f), wi, wo), at(fibre));
    EXPECT_FLOAT_EQ(graded.eval(Vec3(0.9f, 0.5f, 0.5f), wi, wo), at(surface));
    EXPECT_NEAR(graded.eval(Vec3(0.5f, 0.5f, 0.5f), wi, wo), at((fibre + surface) * 0.5f), 1e-6f);
    EXPECT_FLOAT_EQ(graded.projected_area(Vec3(0.1f, 0.5f, 0.5f), Vec3(0, 0, 1)), 0.1f);
    EXPECT_FLOAT_EQ(graded.projected_area(Vec3(0.9f, 0.5f, 0.5f), Vec3(0, 0, 1)), 1.f);
}

TEST(SGGX, RefusesAVolumeThatIsNoMatrixAndMatricesThatAreNotPositiveSemiDefinite) {
    EXPECT_THROW(SGGXPhase(std::make_shared<ConstantVolume>(Color(1.f))), std::invalid_argument);
    EXPECT_THROW(ConstantVolume(SymmetricMatrix3(1, 1, -0.5f, 0, 0, 0)), std::invalid_argument);
    EXPECT_THROW(ConstantVolume(SymmetricMatrix3(1, 1, 1, 2, 0, 0)), std::invalid_argument);  // eigenvalue -1
    EXPECT_THROW(ConstantVolume(SymmetricMatrix3(1, NAN, 1, 0, 0, 0)), std::invalid_argument);
    // Flat and fibre-like limits and the empty matrix are matrices (no flakes there: no extinction).
    EXPECT_NO_THROW(ConstantVolume(SymmetricMatrix3(0, 0, 1, 0, 0, 0)));
    EXPECT_NO_THROW(ConstantVolume(SymmetricMatrix3(0, 0, 0, 0, 0, 0)));
    const Frame r(normalize(Vec3(0.4f, 0.7f, -0.6f)));
    EXPECT_NO_THROW(ConstantVolume(oriented(1.f, 0.f, 0.f, r.s, r.t, r.n)));  // rank 1, rotated: rounding below 0
}

// A microflake medium is denser along some directions: sigma_t = density sigma(d). A homogeneous one's
// majorant along d is exactly that (no null collisions); a heterogeneous one's bounds it over every
// direction (here sigma reaches sqrt(1.5) > 1, which Mitsuba's majorant leaves out).
TEST(SGGX, MicroflakeMediaScaleExtinctionByTheProjectedArea) {
    const SymmetricMatrix3 s(1.5f, 0.5f, 0.04f, 0.f, 0.f, 0.f);
    const auto phase = phase_of(s);
    const auto albedo = std::make_shared<ConstantVolume>(Color(0.8f));
    const HomogeneousMedium homogeneous(Color(2.f), albedo, phase);
    const HeterogeneousMedium heterogeneous(std::make_shared<ConstantVolume>(Color(2.f)), albedo, 1.5f, phase);
    for (const Vec3 &d : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, -1), normalize(Vec3(1, 1, 1))}) {
        const float area = std::sqrt(s.form(d, d));
        EXPECT_FLOAT_EQ(homogeneous.majorant(d).x, 2.f * area);
        EXPECT_FLOAT_EQ(homogeneous.at(kP, d).sigma_t.y, 2.f * area);
        EXPECT_FLOAT_EQ(homogeneous.at(kP, d).sigma_s.z, 1.6f * area);
        EXPECT_FLOAT_EQ(heterogeneous.at(kP, d).sigma_t.x, 3.f * area);
        EXPECT_FLOAT_EQ(heterogeneous.majorant(d).x, 3.f * std::sqrt(1.5f));
    }
    // An isotropic phase function leaves the extinction alone in every direction.
    const HomogeneousMedium plain(Color(2.f), albedo, std::make_shared<IsotropicPhase>());
    EXPECT_EQ(plain.majorant(normalize(Vec3(1, 2, 3))), Color(2.f));
}

// The probability that a ray crosses the unit cube of a heterogeneous sggx medium without a real collision
// (delta tracking: null collisions passed through) is exp(-density sigma(d) length), along each axis.
TEST(SGGX, DeltaTrackingSeesTheDirectionalExtinction) {
    const SymmetricMatrix3 s(1.5f, 0.5f, 0.04f, 0.f, 0.f, 0.f);
    const HeterogeneousMedium m(std::make_shared<ConstantVolume>(Color(1.f)), std::make_shared<ConstantVolume>(Color(1.f)), 1.f,
                                phase_of(s));
    IndependentSampler sampler(11);
    sampler.start_sample(0, 0, 0);
    for (int axis = 0; axis < 3; ++axis) {
        Vec3 d(0.f), o(0.5f);
        d[axis] = 1.f;
        o[axis] = -0.5f;
        const int n = 40000;
        int passed = 0;
        for (int i = 0; i < n; ++i) {
            Ray ray{o, d, 0.f, kInfinity};
            for (;;) {
                const FreeFlight f = sample_free_flight(m, ray, kInfinity, 0, sampler);
                if (f.event == FreeFlight::Null) {
                    ray.tmin = f.t;
                    continue;
                }
                passed += f.event == FreeFlight::Passed;
                break;
            }
        }
        const double expected = std::exp(-std::sqrt(double(s.form(d, d)))), p = double(passed) / n;
        EXPECT_NEAR(p, expected, 4.0 * std::sqrt(expected * (1 - expected) / n)) << "axis " << axis;
    }
}
