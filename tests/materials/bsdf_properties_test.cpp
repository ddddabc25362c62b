// Physical and interface properties of the BSDFs: sample/eval/pdf consistency, reciprocity, energy
// conservation (white furnace), one-sidedness and the dielectric's transport-mode asymmetry.
#include <gtest/gtest.h>

#include "neepp/materials/blendbsdf.h"
#include "neepp/materials/conductor.h"
#include "neepp/materials/dielectric.h"
#include "neepp/materials/diffuse.h"
#include "neepp/materials/fresnel.h"
#include "neepp/materials/normalmap.h"
#include "neepp/materials/plastic.h"
#include "neepp/materials/roughconductor.h"
#include "neepp/materials/pplastic.h"
#include "neepp/materials/roughplastic.h"
#include "neepp/materials/thindielectric.h"
#include "neepp/materials/bumpmap.h"
#include "neepp/materials/mask.h"
#include "neepp/materials/null.h"
#include "neepp/materials/twosided.h"
#include "neepp/sampling/rng.h"

namespace neepp {
namespace {

const BSDFContext kRadiance{TransportMode::Radiance}, kImportance{TransportMode::Importance};

BSDFPtr rough_conductor(MicrofacetType t, float au, float av, float eta = 0.f, float k = 1.f, bool vis = true) {
    return std::make_shared<RoughConductorBSDF>(t, constant_texture(au), constant_texture(av), constant_texture(eta),
                                                constant_texture(k), nullptr, vis);
}

std::vector<BSDFPtr> glossy_bsdfs() {
    return {std::make_shared<DiffuseBSDF>(constant_texture(0.7f)),
            rough_conductor(MicrofacetType::GGX, 0.3f, 0.3f, 0.2f, 3.9f),
            rough_conductor(MicrofacetType::Beckmann, 0.1f, 0.5f, 1.5f, 2.f),
            rough_conductor(MicrofacetType::Beckmann, 0.4f, 0.4f, 0.f, 1.f, false),
            std::make_shared<RoughPlasticBSDF>(MicrofacetType::GGX, 0.2f, 1.5f, 1.f, constant_texture(Color(0.2f, 0.5f, 0.9f))),
            std::make_shared<RoughPlasticBSDF>(MicrofacetType::Beckmann, 0.5f, 1.49f, 1.f, constant_texture(0.6f),
                                               nullptr, true),
            std::make_shared<PlasticBSDF>(1.49f, 1.f, constant_texture(Color(0.8f, 0.3f, 0.1f))),
            std::make_shared<PolarizedPlasticBSDF>(MicrofacetType::Beckmann, constant_texture(0.25f), constant_texture(0.25f),
                                                   1.49f, constant_texture(Color(0.9f, 0.5f, 0.2f))),
            std::make_shared<PolarizedPlasticBSDF>(MicrofacetType::GGX, constant_texture(0.4f), constant_texture(0.15f),
                                                   1.7f, constant_texture(1.f), constant_texture(0.8f), false),
            std::make_shared<BlendBSDF>(constant_texture(0.3f), std::make_shared<DiffuseBSDF>(constant_texture(0.7f)),
                                        rough_conductor(MicrofacetType::GGX, 0.2f, 0.2f, 0.2f, 3.9f)),
            std::make_shared<BlendBSDF>(constant_texture(0.6f), std::make_shared<DiffuseBSDF>(constant_texture(0.5f)),
                                        std::make_shared<ConductorBSDF>(constant_texture(0.f), constant_texture(1.f)))};
}

// Normal maps over a diffuse and a rough plastic: a tilted normal, one that flip_invalid_normals mirrors
// for most wi, and the same without Mitsuba's two defaults.
std::vector<BSDFPtr> normal_mapped_bsdfs() {
    const BSDFPtr diffuse = std::make_shared<DiffuseBSDF>(constant_texture(0.7f));
    const BSDFPtr plastic = std::make_shared<RoughPlasticBSDF>(MicrofacetType::GGX, 0.2f, 1.5f, 1.f, constant_texture(0.5f));
    const TexturePtr tilted = constant_texture(Color(0.65f, 0.4f, 0.9f)), away = constant_texture(Color(0.2f, 0.25f, 0.65f));
    return {std::make_shared<NormalMapBSDF>(tilted, diffuse), std::make_shared<NormalMapBSDF>(away, plastic),
            std::make_shared<NormalMapBSDF>(tilted, plastic, false, false)};
}

Vec3 random_direction(PCG32 &rng, bool upper) {
    Vec2 u = rng.next_2d();
    float z = upper ? 0.02f + 0.98f * u.y : 1.f - 2.f * u.y, r = safe_sqrt(1 - z * z), phi = 2 * kPi * u.x;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

void expect_rel(const Color &a, const Color &b, float tol, const std::string &what) {
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tol * std::max(1e-3f, std::abs(b[i]))) << what << " [" << i << "]";
}

TEST(BSDFProperties, SampleWeightIsEvalOverPdfForSmoothLobes) {
    PCG32 rng(7, 1);
    SurfaceInteraction si;
    int checked = 0;
    for (const auto &bsdf : glossy_bsdfs())
        for (int i = 0; i < 2000; ++i) {
            Vec3 wi = random_direction(rng, true);
            si.wi = wi;
            BSDFSample bs = bsdf->sample(kRadiance, si, wi, rng.next_float(), rng.next_2d());
            if (!bs.valid() || (bs.sampled_flags & BSDFDelta)) continue;
            EXPECT_TRUE(bs.sampled_flags & bsdf->flags());
            float pdf = bsdf->pdf(kRadiance, si, wi, bs.wo);
            EXPECT_NEAR(bs.pdf, pdf, 1e-3f * pdf);
            expect_rel(bs.weight * bs.pdf, bsdf->eval(kRadiance, si, wi, bs.wo), 2e-3f, "weight * pdf vs eval");
            ++checked;
        }
    EXPECT_GT(checked, 10000);
}

// eval_pdf (what next event estimation calls) is eval and pdf at once, including through the wrappers
// that forward it and for directions on either side.
TEST(BSDFProperties, EvalPdfIsEvalAndPdf) {
    std::vector<BSDFPtr> bsdfs = glossy_bsdfs();
    const BSDFPtr rp = bsdfs[4], rc = bsdfs[1];
    bsdfs.push_back(std::make_shared<TwoSidedBSDF>(rp, rc));
    bsdfs.push_back(std::make_shared<MaskBSDF>(constant_texture(0.6f), rc));
    bsdfs.push_back(std::make_shared<BumpMapBSDF>(constant_texture(0.3f), 1.f, rp));
    for (const BSDFPtr &b : normal_mapped_bsdfs()) bsdfs.push_back(b);
    PCG32 rng(11, 3);
    SurfaceInteraction si;
    int nonzero = 0;
    for (const auto &bsdf : bsdfs)
        for (int i = 0; i < 500; ++i) {
            const Vec3 wi = random_direction(rng, false), wo = random_direction(rng, false);
            si.wi = wi;
            const BSDFEval e = bsdf->eval_pdf(kRadiance, si, wi, wo);
            const Color f = bsdf->eval(kRadiance, si, wi, wo);
            for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(e.f[c], f[c]);
            EXPECT_FLOAT_EQ(e.pdf, bsdf->pdf(kRadiance, si, wi, wo));
            nonzero += e.pdf > 0 && !is_black(e.f);
        }
    EXPECT_GT(nonzero, 1000);
}

TEST(BSDFProperties, ReflectionIsReciprocalAndOneSided) {
    PCG32 rng(3, 2);
    SurfaceInteraction si;
    for (const auto &bsdf : glossy_bsdfs())
        for (int i = 0; i < 500; ++i) {
            Vec3 a = random_direction(rng, true), b = random_direction(rng, true);
            // f(a, b) = f(b, a), with eval carrying |cos| of its second argument.
            Color f_ab = bsdf->eval(kRadiance, si, a, b) / b.z, f_ba = bsdf->eval(kImportance, si, b, a) / a.z;
            expect_rel(f_ab, f_ba, 2e-3f, "reciprocity");
            Vec3 below(b.x, b.y, -b.z);
            EXPECT_TRUE(is_black(bsdf->eval(kRadiance, si, below, b)));
            EXPECT_TRUE(is_black(bsdf->eval(kRadiance, si, a, below)));
            EXPECT_EQ(bsdf->pdf(kRadiance, si, below, b), 0.f);
            EXPECT_FALSE(bsdf->sample(kRadiance, si, below, rng.next_float(), rng.next_2d()).valid());
        }
}

// Albedo by importance sampling (mean weight) and by uniform sampling of eval: the two agree only if
// eval is normalized consistently with the sampler.
std::pair<double, double> albedo_two_ways(const BSDF &bsdf, const Vec3 &wi, int n) {
    PCG32 rng(11, 5);
    SurfaceInteraction si;
    si.wi = wi;
    double is = 0, uniform = 0;
    for (int i = 0; i < n; ++i) {
        BSDFSample bs = bsdf.sample(kRadiance, si, wi, rng.next_float(), rng.next_2d());
        if (bs.valid()) is += bs.weight.y;
        Vec3 wo = random_direction(rng, false);
        uniform += bsdf.eval(kRadiance, si, wi, wo).y * 4 * kPi;
    }
    return {is / n, uniform / n};
}

TEST(BSDFProperties, WhiteFurnaceOfRoughMirror) {
    for (auto type : {MicrofacetType::GGX, MicrofacetType::Beckmann}) {
        // Perfect-mirror Fresnel: only single-scattering loss remains, negligible when smooth.
        auto smooth = rough_conductor(type, 0.05f, 0.05f);
        double albedo = albedo_two_ways(*smooth, normalize(Vec3(0.3f, 0.1f, 0.9f)), 100000).first;
        EXPECT_NEAR(albedo, 1.0, 5e-3);
        // Rougher: energy is lost to shadowing, but eval integrates to what sampling reports.
        auto rough = rough_conductor(type, 0.5f, 0.5f);
        auto [is, uni] = albedo_two_ways(*rough, normalize(Vec3(0.5f, 0.f, 0.7f)), 400000);
        // Single-scattering albedo at alpha 0.5, as Mitsuba 3 estimates it (GGX's long tail shadows more).
        EXPECT_NEAR(is, type == MicrofacetType::GGX ? 0.677 : 0.890, 0.01);
        EXPECT_NEAR(is, uni, 0.02);
    }
    // Smooth mirror is exact.
    ConductorBSDF mirror(constant_texture(0.f), constant_texture(1.f));
    SurfaceInteraction si;
    Vec3 wi = normalize(Vec3(0.2f, 0.4f, 0.3f));
    BSDFSample bs = mirror.sample(kRadiance, si, wi, 0.5f, Vec2(0.5f, 0.5f));
    EXPECT_NEAR(bs.weight.x, 1.f, 1e-6f);
    EXPECT_EQ(bs.wo, Vec3(-wi.x, -wi.y, wi.z));
}

// Albedo never exceeds one, and eval integrates to what sampling reports (delta lobes excluded).
TEST(BSDFProperties, ReflectorsConserveEnergy) {
    for (const auto &bsdf : glossy_bsdfs()) {
        for (float z : {0.1f, 0.5f, 0.95f}) {
            Vec3 wi(std::sqrt(1 - z * z), 0.f, z);
            auto [is, uni] = albedo_two_ways(*bsdf, wi, 100000);
            EXPECT_LT(is, 1.0 + 1e-2);
            if (!(bsdf->flags() & BSDFDelta)) {
                EXPECT_NEAR(is, uni, 0.03 * std::max(is, 0.1));
            }
        }
    }
}

// A shading normal is not reciprocal (Mitsuba's normal map is not either), but sampling must still
// report what eval integrates to, the albedo stays below the nested BSDF's, and the sample weight is
// eval / pdf through the frame change, the flip and the shadowing term.
TEST(NormalMap, SamplingAgreesWithEvalAndAlbedoStaysBelowOne) {
    PCG32 rng(5, 8);
    const std::vector<BSDFPtr> bsdfs = normal_mapped_bsdfs();
    for (size_t k = 0; k < bsdfs.size(); ++k) {
        const BSDFPtr &bsdf = bsdfs[k];
        for (float z : {0.1f, 0.5f, 0.95f}) {
            const Vec3 wi(0.f, std::sqrt(1 - z * z), z);
            auto [is, uni] = albedo_two_ways(*bsdf, wi, 100000);
            EXPECT_LT(is, 1.0 + 1e-2);
            // Without the flip, the grazing wi lies behind the tilted normal and the surface is black there
            // (the seam that Mitsuba's default removes); else light is reflected.
            if (k == 2 && z < 0.2f) EXPECT_EQ(is, 0.0);
            else EXPECT_GT(is, 0.05) << k << " " << z;
            EXPECT_NEAR(is, uni, 0.03 * std::max(is, 0.1)) << z;
        }
        SurfaceInteraction si;
        int checked = 0;
        for (int i = 0; i < 2000; ++i) {
            const Vec3 wi = random_direction(rng, true);
            si.wi = wi;
            const BSDFSample bs = bsdf->sample(kRadiance, si, wi, rng.next_float(), rng.next_2d());
            if (!bs.valid()) continue;
            EXPECT_NEAR(bs.pdf, bsdf->pdf(kRadiance, si, wi, bs.wo), 1e-3f * bs.pdf);
            expect_rel(bs.weight * bs.pdf, bsdf->eval(kRadiance, si, wi, bs.wo), 2e-3f, "normalmap weight * pdf vs eval");
            ++checked;
        }
        EXPECT_GT(checked, 1000);
    }
}

// Mitsuba's normal map frame: n = 2 c - 1 in the hit's shading frame, normalized, s the frame's own s made
// orthogonal to it; the neutral colour (0.5, 0.5, 1) leaves the nested BSDF exactly as it is (its
// shadowing term is 1 for an unperturbed normal).
TEST(NormalMap, FrameIsMitsubasAndNeutralColourChangesNothing) {
    SurfaceInteraction si;
    si.sh_frame = Frame(normalize(Vec3(1, 1, 0)), Vec3(0, 0, 1), normalize(Vec3(1, -1, 0)));
    si.n = si.sh_frame.n;
    const Vec3 wi = normalize(Vec3(0.2f, 0.1f, 0.9f));
    si.wi = wi;
    const BSDFPtr diffuse = std::make_shared<DiffuseBSDF>(constant_texture(0.7f));
    const NormalMapBSDF tilted(constant_texture(Color(0.65f, 0.4f, 0.9f)), diffuse);
    const Frame f = tilted.perturbed_frame(si, wi);
    const Vec3 n = normalize(Vec3(0.3f, -0.2f, 0.8f)), s = normalize(Vec3(1, 0, 0) - n * n.x);
    EXPECT_NEAR(norm(f.n - si.to_world(n)), 0.f, 1e-5f);
    EXPECT_NEAR(norm(f.s - si.to_world(s)), 0.f, 1e-5f);
    EXPECT_NEAR(norm(f.t - si.to_world(cross(n, s))), 0.f, 1e-5f);
    // Seen from the side the normal leans away from, it is mirrored about the unperturbed one.
    const Vec3 grazing = normalize(Vec3(-0.9f, 0.6f, 0.1f));
    EXPECT_NEAR(norm(tilted.perturbed_frame(si, grazing).n - si.to_world(Vec3(-n.x, -n.y, n.z))), 0.f, 1e-5f);
    const NormalMapBSDF neutral(constant_texture(Color(0.5f, 0.5f, 1.f)), diffuse);
    PCG32 rng(2, 2);
    for (int i = 0; i < 100; ++i) {
        const Vec3 a = random_direction(rng, true), b = random_direction(rng, true);
        expect_rel(neutral.eval(kRadiance, si, a, b), diffuse->eval(kRadiance, si, a, b), 1e-5f, "neutral normal map");
    }
}

// blendbsdf: weight 0 is the first BSDF, 1 the second (Mitsuba's order), in between the linear blend of
// eval and pdf; a delta lobe sampled keeps its weight and its pdf is scaled by the probability of its pick.
TEST(BlendBSDF, WeightsFollowMitsubasOrder) {
    const BSDFPtr diffuse = std::make_shared<DiffuseBSDF>(constant_texture(0.7f));
    const BSDFPtr glossy = rough_conductor(MicrofacetType::GGX, 0.2f, 0.2f, 0.2f, 3.9f);
    SurfaceInteraction si;
    PCG32 rng(4, 4);
    for (float w : {0.f, 0.25f, 1.f}) {
        const BlendBSDF blend(constant_texture(w), diffuse, glossy);
        for (int i = 0; i < 200; ++i) {
            const Vec3 a = random_direction(rng, true), b = random_direction(rng, true);
            expect_rel(blend.eval(kRadiance, si, a, b),
                       diffuse->eval(kRadiance, si, a, b) * (1 - w) + glossy->eval(kRadiance, si, a, b) * w, 1e-5f, "blend");
            EXPECT_NEAR(blend.pdf(kRadiance, si, a, b),
                        diffuse->pdf(kRadiance, si, a, b) * (1 - w) + glossy->pdf(kRadiance, si, a, b) * w,
                        1e-5f * glossy->pdf(kRadiance, si, a, b) + 1e-7f);
        }
    }
    // Weights outside [0, 1] are clamped, as Mitsuba does.
    const Vec3 a = normalize(Vec3(0.1f, 0.2f, 0.9f)), b = normalize(Vec3(-0.3f, 0.1f, 0.8f));
    expect_rel(BlendBSDF(constant_texture(1.7f), diffuse, glossy).eval(kRadiance, si, a, b),
               glossy->eval(kRadiance, si, a, b), 1e-6f, "clamped");
    const ConductorBSDF mirror(constant_texture(0.f), constant_texture(1.f));
    const BlendBSDF half(constant_texture(0.6f), diffuse, std::make_shared<ConductorBSDF>(constant_texture(0.f), constant_texture(1.f)));
    const BSDFSample bs = half.sample(kRadiance, si, a, 0.3f, Vec2(0.4f, 0.4f));
    ASSERT_EQ(bs.sampled_flags, BSDFDeltaReflection);
    EXPECT_NEAR(bs.pdf, 0.6f, 1e-6f);
    expect_rel(bs.weight, mirror.sample(kRadiance, si, a, 0.3f, Vec2(0.4f, 0.4f)).weight, 1e-6f, "delta weight");
    EXPECT_EQ(half.sample(kRadiance, si, a, 0.7f, Vec2(0.4f, 0.4f)).sampled_flags, BSDFDiffuseReflection);
}

TEST(BSDFProperties, RoughPlasticTablesAreSensible) {
    RoughPlasticBSDF p(MicrofacetType::GGX, 0.05f, 1.5f, 1.f, constant_texture(0.5f));
    // Almost smooth: the tabulated transmittance approaches 1 - Fresnel.
    for (float c : {0.3f, 0.7f, 1.f}) EXPECT_NEAR(p.external_transmittance(c), 1 - fresnel_dielectric(c, 1.5f).r, 0.02f);
    // Mitsuba's table loses some grazing energy to masking and averages 64 cosines with equal weights.
    EXPECT_NEAR(p.internal_reflectance(), fresnel_diffuse_reflectance(1 / 1.5f), 0.04f);
}

TEST(BSDFProperties, RoughPlasticTablesAreSharedOnlyBetweenEqualCoatings) {
    // The tables are computed once per (distribution, alpha, eta): a second material with the same coating
    // gets the same tables, one that differs in any of the three gets its own.
    auto tables = [](MicrofacetType type, float alpha, float ior) {
        RoughPlasticBSDF p(type, alpha, ior, 1.f, constant_texture(0.5f));
        std::vector<float> t{p.internal_reflectance()};
        for (int i = 0; i <= 10; ++i) t.push_back(p.external_transmittance(float(i) / 10.f));
        return t;
    };
    const auto a = tables(MicrofacetType::GGX, 0.3f, 1.5f);
    EXPECT_EQ(tables(MicrofacetType::GGX, 0.3f, 1.5f), a);
    EXPECT_NE(tables(MicrofacetType::GGX, 0.31f, 1.5f), a);
    EXPECT_NE(tables(MicrofacetType::GGX, 0.3f, 1.6f), a);
    EXPECT_NE(tables(MicrofacetType::Beckmann, 0.3f, 1.5f), a);
}

TEST(Dielectric, ReflectionPlusTransmissionIsOneAndModesDifferByEta2) {
    DielectricBSDF glass(1.5f, 1.f);
    SurfaceInteraction si;
    for (float z : {0.9f, 0.4f, -0.4f, -0.9f}) {
        Vec3 wi(std::sqrt(1 - z * z), 0.f, z);
        FresnelResult f = fresnel_dielectric(z, 1.5f);
        PCG32 rng(1, 9);
        int n = 200000, reflected = 0;
        for (int i = 0; i < n; ++i) {
            float u = rng.next_float();
            BSDFSample rad = glass.sample(kRadiance, si, wi, u, Vec2()), imp = glass.sample(kImportance, si, wi, u, Vec2());
            ASSERT_TRUE(rad.valid());
            if (rad.sampled_flags == BSDFDeltaReflection) {
                ++reflected;
                EXPECT_EQ(rad.wo, Vec3(-wi.x, -wi.y, wi.z));
                EXPECT_FLOAT_EQ(rad.weight.x, imp.weight.x);
            } else {
                ASSERT_EQ(rad.sampled_flags, BSDFDeltaTransmission);
                EXPECT_LT(rad.wo.z * wi.z, 0.f);
                EXPECT_NEAR(norm(rad.wo), 1.f, 1e-5f);
                EXPECT_FLOAT_EQ(rad.eta, z > 0 ? 1.5f : 1 / 1.5f);
                // Radiance is compressed entering glass (and expanded leaving it); importance is not.
                EXPECT_FLOAT_EQ(imp.weight.x, 1.f);
                EXPECT_NEAR(rad.weight.x * rad.eta * rad.eta, 1.f, 1e-5f);
            }
            // pdf * weight = the lobe's energy: r for reflection, (1 - r) for transmission (importance).
            float lobe = imp.sampled_flags == BSDFDeltaReflection ? f.r : 1 - f.r;
            EXPECT_NEAR(imp.pdf * imp.weight.x, lobe, 1e-6f);
        }
        double frac = double(reflected) / n;
        EXPECT_NEAR(frac, f.r, 4 * std::sqrt(f.r * (1 - f.r) / n) + 1e-4) << z;
        EXPECT_TRUE(is_black(glass.eval(kRadiance, si, wi, Vec3(0, 0, 1))));
    }
}

TEST(ThinDielectric, InterreflectionSumAndStraightTransmission) {
    ThinDielectricBSDF pane(1.5f, 1.f);
    SurfaceInteraction si;
    for (float z : {0.8f, 0.2f, -0.5f}) {
        Vec3 wi(std::sqrt(1 - z * z), 0.f, z);
        float r = fresnel_dielectric(std::abs(z), 1.5f).r, t = 1 - r;
        float expected = r + t * t * r / (1 - r * r);
        EXPECT_NEAR(pane.reflectance(wi), expected, 1e-6f);
        BSDFSample refl = pane.sample(kRadiance, si, wi, 0.f, Vec2());
        BSDFSample trans = pane.sample(kRadiance, si, wi, 0.999f, Vec2());
        EXPECT_EQ(refl.sampled_flags, BSDFDeltaReflection);
        EXPECT_NEAR(refl.pdf, expected, 1e-6f);
        EXPECT_EQ(trans.wo, -wi);
        EXPECT_EQ(trans.sampled_flags, BSDFNull);
        EXPECT_NEAR(trans.pdf, 1 - expected, 1e-6f);
        EXPECT_EQ(trans.eta, 1.f);
        EXPECT_NEAR(pane.null_transmission(si, wi).x, 1 - expected, 1e-6f);
    }
}

TEST(SmoothBSDFs, ConductorAndPlasticDeltaLobes) {
    SurfaceInteraction si;
    Vec3 wi = normalize(Vec3(0.3f, -0.4f, 0.6f));
    ConductorBSDF cu(constant_texture(Color(0.2f, 0.92f, 1.1f)), constant_texture(Color(3.9f, 2.45f, 2.14f)),
                     constant_texture(0.5f));
    BSDFSample bs = cu.sample(kRadiance, si, wi, 0.3f, Vec2(0.1f, 0.2f));
    expect_rel(bs.weight, fresnel_conductor(wi.z, Color(0.2f, 0.92f, 1.1f), Color(3.9f, 2.45f, 2.14f)) * 0.5f, 1e-6f,
               "conductor");
    EXPECT_FALSE(cu.sample(kRadiance, si, Vec3(wi.x, wi.y, -wi.z), 0.3f, Vec2()).valid());

    // Plastic: with black diffuse every sample is the delta lobe, weighted by the coating's Fresnel.
    PlasticBSDF black(1.5f, 1.f, constant_texture(0.f));
    bs = black.sample(kRadiance, si, wi, 0.999f, Vec2(0.3f, 0.3f));
    EXPECT_EQ(bs.sampled_flags, BSDFDeltaReflection);
    EXPECT_NEAR(bs.weight.x, fresnel_dielectric(wi.z, 1.5f).r, 1e-6f);
    EXPECT_NEAR(bs.pdf, 1.f, 1e-6f);
}

}  // namespace
}  // namespace neepp
