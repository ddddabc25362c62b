// Chi-square goodness of fit of every non-delta BSDF's sampling against its pdf, over incident angles
// from normal to grazing, roughness 0.05..0.8, both distributions, anisotropy and both normal samplers,
// and of the wrappers that sample a nested BSDF their own way (blendbsdf, normalmap).
#include <gtest/gtest.h>

#include <functional>
#include <sstream>

#include "chi2.h"
#include "neepp/materials/blendbsdf.h"
#include "neepp/textures/checkerboard_texture.h"
#include "neepp/materials/conductor.h"
#include "neepp/materials/diffuse.h"
#include "neepp/materials/normalmap.h"
#include "neepp/materials/plastic.h"
#include "neepp/materials/roughconductor.h"
#include "neepp/materials/pplastic.h"
#include "neepp/materials/roughplastic.h"

namespace neepp::test {
namespace {

struct Case {
    std::string name;
    std::function<BSDFPtr()> make;
    float theta_deg;
    int ires = 4;
};

Vec3 incident(float theta_deg) {
    float t = theta_deg * kPi / 180.f;
    // A non-zero azimuth, so that anisotropic lobes are not aligned with the bins.
    return Vec3(std::sin(t) * std::cos(0.7f), std::sin(t) * std::sin(0.7f), std::cos(t));
}

std::vector<Case> make_cases() {
    std::vector<Case> cases;
    auto add = [&](std::string name, std::function<BSDFPtr()> make, std::vector<float> thetas, int ires = 4) {
        for (float t : thetas) cases.push_back({name, make, t, ires});
    };
    add("diffuse", [] { return std::make_shared<DiffuseBSDF>(constant_texture(0.5f)); }, {0.f, 50.f, 89.f});

    for (auto type : {MicrofacetType::GGX, MicrofacetType::Beckmann}) {
        std::string dn = type == MicrofacetType::GGX ? "ggx" : "beckmann";
        for (float alpha : {0.05f, 0.2f, 0.8f}) {
            auto make = [=] {
                auto a = constant_texture(alpha);
                return std::make_shared<RoughConductorBSDF>(type, a, a, constant_texture(0.2f), constant_texture(3.f));
            };
            std::string name = "roughconductor_" + dn + "_a" + std::to_string(alpha);
            if (alpha < 0.1f) {
                // Narrow lobes need a finer pdf quadrature, finest where the horizon cuts them. At normal
                // incidence this lobe fits inside the bin row around the pole, which Simpson's rule cannot
                // resolve, so it is tested off-normal only.
                add(name, make, {30.f, 70.f}, 12);
                add(name, make, {88.f}, 24);
            } else {
                add(name, make, {0.f, 45.f, 75.f, 88.f});
            }
        }
        add("roughconductor_" + dn + "_aniso_0.1_0.5", [=] {
            return std::make_shared<RoughConductorBSDF>(type, constant_texture(0.1f), constant_texture(0.5f),
                                                        constant_texture(0.f), constant_texture(1.f));
        }, {0.f, 40.f, 80.f}, 8);
        add("roughconductor_" + dn + "_aniso_0.6_0.2", [=] {
            return std::make_shared<RoughConductorBSDF>(type, constant_texture(0.6f), constant_texture(0.2f),
                                                        constant_texture(0.f), constant_texture(1.f));
        }, {60.f});
        add("roughconductor_" + dn + "_allnormals", [=] {
            return std::make_shared<RoughConductorBSDF>(type, constant_texture(0.3f), constant_texture(0.15f),
                                                        constant_texture(0.f), constant_texture(1.f), nullptr, false);
        }, {20.f, 70.f});
        for (float alpha : {0.1f, 0.4f}) {
            add("roughplastic_" + dn + "_a" + std::to_string(alpha), [=] {
                return std::make_shared<RoughPlasticBSDF>(type, alpha, 1.5f, 1.f, constant_texture(Color(0.2f, 0.5f, 0.8f)));
            }, {0.f, 60.f, 85.f});
        }
    }
    add("roughplastic_beckmann_allnormals_nonlinear", [] {
        return std::make_shared<RoughPlasticBSDF>(MicrofacetType::Beckmann, 0.3f, 1.7f, 1.f, constant_texture(0.7f),
                                                  nullptr, true, false);
    }, {45.f});
    // pplastic: its own mixture (specular weight only, two smooth Fresnel transmissions on the diffuse lobe).
    add("pplastic_beckmann_default", [] {
        auto a = constant_texture(0.1f);
        return std::make_shared<PolarizedPlasticBSDF>(MicrofacetType::Beckmann, a, a, 1.49f, constant_texture(0.5f));
    }, {0.f, 60.f, 85.f});
    add("pplastic_ggx_aniso_allnormals", [] {
        return std::make_shared<PolarizedPlasticBSDF>(MicrofacetType::GGX, constant_texture(0.3f), constant_texture(0.1f),
                                                      1.6f, constant_texture(Color(0.05f, 0.03f, 0.1f)), nullptr, false);
    }, {30.f, 75.f});
    add("plastic", [] { return std::make_shared<PlasticBSDF>(1.49f, 1.f, constant_texture(0.5f)); }, {10.f, 80.f});

    // blendbsdf: the pick by weight and the blended pdf. A float weight, a texture one (the checkerboard's
    // color0 at the harness's uv), and a delta lobe, whose samples the pdf leaves out, scaled by its pick.
    auto glossy = [] {
        auto a = constant_texture(0.2f);
        return std::make_shared<RoughConductorBSDF>(MicrofacetType::GGX, a, a, constant_texture(0.2f), constant_texture(3.f));
    };
    auto diffuse = [] { return std::make_shared<DiffuseBSDF>(constant_texture(Color(0.8f, 0.5f, 0.3f))); };
    add("blend_diffuse_roughconductor_w0.3", [=] {
        return std::make_shared<BlendBSDF>(constant_texture(0.3f), diffuse(), glossy());
    }, {0.f, 45.f, 80.f});
    add("blend_textured_weight", [=] {
        auto weight = std::make_shared<CheckerboardTexture>(constant_texture(0.7f), constant_texture(0.1f), Transform());
        return std::make_shared<BlendBSDF>(weight, glossy(), diffuse());
    }, {30.f});
    add("blend_diffuse_mirror_w0.4", [=] {
        return std::make_shared<BlendBSDF>(constant_texture(0.4f), diffuse(),
                                           std::make_shared<ConductorBSDF>(constant_texture(0.f), constant_texture(1.f)));
    }, {20.f});
    // normalmap: a constant tilted tangent-space normal, (0.3, -0.2, 0.8) before normalization, with and
    // without Mitsuba's two defaults; and one tilted away from these wi, (-0.6, -0.5, 0.3), which
    // flip_invalid_normals mirrors except at normal incidence.
    const Color tilted(0.65f, 0.4f, 0.9f), away(0.2f, 0.25f, 0.65f);
    add("normalmap_diffuse", [=] { return std::make_shared<NormalMapBSDF>(constant_texture(tilted), diffuse()); },
        {0.f, 50.f, 85.f});
    add("normalmap_diffuse_flipped", [=] { return std::make_shared<NormalMapBSDF>(constant_texture(away), diffuse()); },
        {0.f, 50.f, 85.f});
    add("normalmap_roughplastic", [=] {
        return std::make_shared<NormalMapBSDF>(constant_texture(tilted),
            std::make_shared<RoughPlasticBSDF>(MicrofacetType::GGX, 0.3f, 1.5f, 1.f, constant_texture(0.5f)));
    }, {20.f, 70.f});
    add("normalmap_roughplastic_noflip_noshadowing", [=] {
        return std::make_shared<NormalMapBSDF>(constant_texture(tilted),
            std::make_shared<RoughPlasticBSDF>(MicrofacetType::Beckmann, 0.2f, 1.5f, 1.f, constant_texture(0.5f)),
            false, false);
    }, {40.f});
    return cases;
}

const std::vector<Case> &cases() {
    static const std::vector<Case> c = make_cases();
    return c;
}

class Chi2BSDF : public ::testing::TestWithParam<size_t> {};

TEST_P(Chi2BSDF, SamplingMatchesPdf) {
    const Case &c = cases()[GetParam()];
    BSDFPtr bsdf = c.make();
    Chi2Config cfg;
    cfg.sample_count = 400000;
    cfg.ires = c.ires;
    cfg.seed = 1000 + GetParam();
    Chi2Result r = chi2_test(*bsdf, incident(c.theta_deg), cfg);
    SCOPED_TRACE(c.name + " theta=" + std::to_string(c.theta_deg) + ": " + r.describe());
    ASSERT_TRUE(r.error.empty());
    // Bonferroni correction over all cases, so that one run of the suite has a 1% false-alarm rate.
    EXPECT_GT(r.p_value, 0.01 / double(cases().size()));
    // Sampling density may lose mass (directions below the horizon) but never create it.
    EXPECT_LE(r.pdf_integral, 1.0 + 2e-3);
    EXPECT_NEAR(r.pdf_integral, r.valid_fraction, 0.01);
}

INSTANTIATE_TEST_SUITE_P(AllBSDFs, Chi2BSDF, ::testing::Range<size_t>(0, cases().size()),
                         [](const ::testing::TestParamInfo<size_t> &info) {
                             const Case &c = cases()[info.param];
                             std::string s = c.name + "_theta" + std::to_string(int(c.theta_deg));
                             for (char &ch : s)
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return s + "_" + std::to_string(info.param);
                         });

}  // namespace
}  // namespace neepp::test
