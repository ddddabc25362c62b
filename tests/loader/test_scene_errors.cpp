// Bad input gets a clear error naming the file (and line where there is one), never a crash or a hang.
#include <gtest/gtest.h>
#include <fstream>
#include "neepp/io/scene_error.h"
#include "neepp/materials/blendbsdf.h"
#include "neepp/materials/hair.h"
#include "neepp/materials/normalmap.h"
#include "neepp/materials/principled.h"
#include "neepp/materials/principledthin.h"
#include "neepp/media/blend_phase.h"
#include "neepp/media/phase_functions.h"
#include "neepp/media/sggx_phase.h"
#include "neepp/media/tabulated_phase.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

const char *kCamera = R"(<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>)";
const char *kLight = R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)";

std::string scene_with(const std::string &body) {
    return std::string("<scene version=\"3.0.0\">\n") + kCamera + "\n" + body + "\n</scene>\n";
}

// Loads xml and returns the error message; fails the test if it loads.
std::string load_error(const std::string &xml, const std::string &file_name = "scene.xml") {
    std::string path = write_temp_scene(xml, file_name);
    try {
        load_scene(path);
    } catch (const std::exception &e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find(file_name), std::string::npos) << "message does not name the file: " << msg;
        return msg;
    }
    ADD_FAILURE() << "scene loaded but should not have:\n" << xml;
    return "";
}

// Objects nested through <ref>s: a chain as deep as the loader allows builds (the factories recurse along
// it), one deeper is an error at its line; nested instancing is refused whatever the depth.
TEST(SceneErrors, NestingThroughRefsIsBounded) {
    auto chain = [](int n) {
        std::string body = "<bsdf type=\"diffuse\" id=\"b0\"/>\n";
        for (int i = 1; i < n; ++i)
            body += "<bsdf type=\"twosided\" id=\"b" + std::to_string(i) + "\"><ref id=\"b" + std::to_string(i - 1) +
                    "\"/></bsdf>\n";
        return scene_with(body + "<shape type=\"sphere\"><ref id=\"b" + std::to_string(n - 1) + "\"/></shape>\n" + kLight);
    };
    auto scene = load_scene(write_temp_scene(chain(97)));  // scene > shape > 97 BSDFs: 99 objects deep
    ASSERT_EQ(scene->shapes().size(), 1u);
    EXPECT_TRUE(scene->shapes()[0]->bsdf->has_flag(BSDFDiffuseReflection));
    EXPECT_NE(load_error(chain(200000)).find("more than 100 deep"), std::string::npos);
    // Blends of blends of one shared BSDF: 2^depth evaluations at every shading point, refused past 64.
    auto blends = [](int n) {
        std::string body = "<bsdf type=\"diffuse\" id=\"b0\"/>\n";
        for (int i = 1; i < n; ++i)
            body += "<bsdf type=\"blendbsdf\" id=\"b" + std::to_string(i) + "\"><float name=\"weight\" value=\"0.5\"/><ref id=\"b" + std::to_string(i - 1) +
                    "\"/><ref id=\"b" + std::to_string(i - 1) + "\"/></bsdf>\n";
        return scene_with(body + "<shape type=\"sphere\"><ref id=\"b" + std::to_string(n - 1) + "\"/></shape>\n" + kLight);
    };
    EXPECT_NO_THROW(load_scene(write_temp_scene(blends(7))));  // 64 evaluations
    EXPECT_NE(load_error(blends(60)).find("evaluates 128 nested BSDFs"), std::string::npos);
    // Textures that each use the previous one twice, and twosided BSDFs whose back is their front: what
    // the loader asks of them once (a mean, flags, the mesh attributes they read) must not take 2^depth
    // calls (it took longer than any test runs, before).
    std::string textures = "<texture type=\"checkerboard\" id=\"t0\"/>\n";
    for (int i = 1; i < 60; ++i)
        textures += "<texture type=\"checkerboard\" id=\"t" + std::to_string(i) + "\"><ref name=\"color0\" id=\"t" +
                    std::to_string(i - 1) + "\"/><ref name=\"color1\" id=\"t" + std::to_string(i - 1) + "\"/></texture>\n";
    auto textured = load_scene(write_temp_scene(scene_with(
        textures + "<shape type=\"sphere\"><bsdf type=\"diffuse\"><ref name=\"reflectance\" id=\"t59\"/></bsdf>"
                   "<emitter type=\"area\"><ref name=\"radiance\" id=\"t59\"/></emitter></shape>\n")));
    EXPECT_EQ(textured->lights().size(), 1u);
}

TEST(SceneErrors, MalformedXmlNamesFileAndLine) {
    std::string msg = load_error("<scene version=\"3.0.0\">\n<shape type=\"sphere\">\n</scene>\n", "broken.xml");
    EXPECT_NE(msg.find("broken.xml:"), std::string::npos) << msg;
}

TEST(SceneErrors, UnknownPluginsAreRejectedWithTheirLine) {
    EXPECT_NE(load_error(scene_with(std::string(kLight) + "\n<shape type=\"teapot\"/>")).find(":4:"), std::string::npos);
    EXPECT_NE(load_error(scene_with(std::string(kLight) + "\n<shape type=\"sphere\"><bsdf type=\"velvet\"/></shape>")).find("velvet"),
              std::string::npos);
    EXPECT_NE(load_error(scene_with("<emitter type=\"sunsky\"/>")).find("sunsky"), std::string::npos);
    EXPECT_NE(load_error(scene_with(std::string(kLight) + "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"noise\"/></bsdf></shape>")).find("noise"),
              std::string::npos);
}

TEST(SceneErrors, MissingMeshAndTextureNameThePath) {
    std::string msg = load_error(scene_with(std::string(kLight) + R"(<shape type="obj"><string name="filename" value="nowhere/mesh.obj"/></shape>)"));
    EXPECT_NE(msg.find("nowhere/mesh.obj"), std::string::npos) << msg;
    msg = load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><bsdf type="diffuse">
        <texture name="reflectance" type="bitmap"><string name="filename" value="missing_tex.png"/></texture></bsdf></shape>)"));
    EXPECT_NE(msg.find("missing_tex.png"), std::string::npos) << msg;
}

TEST(SceneErrors, NanVerticesAreRejected) {
    std::string path = write_temp_scene(scene_with(std::string(kLight) + R"(<shape type="obj"><string name="filename" value="bad.obj"/></shape>)"));
    std::ofstream(std::filesystem::path(path).parent_path() / "bad.obj") << "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n";
    try {
        load_scene(path);
        FAIL() << "NaN vertex accepted";
    } catch (const std::exception &e) {
        EXPECT_NE(std::string(e.what()).find("bad.obj"), std::string::npos) << e.what();
    }
}

TEST(SceneErrors, EmptySceneAndSceneWithoutLights) {
    EXPECT_NE(load_error("<scene version=\"3.0.0\"/>").find("light"), std::string::npos);
    EXPECT_NE(load_error(scene_with("<shape type=\"sphere\"/>")).find("no light"), std::string::npos);
}

TEST(SceneErrors, AbsurdResolutionIsRejected) {
    std::string xml = std::string("<scene version=\"3.0.0\">") +
                      R"(<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="1000000"/><integer name="height" value="1000000"/></film></sensor>)" +
                      kLight + "</scene>";
    EXPECT_NE(load_error(xml).find("out of range"), std::string::npos);
    xml = std::string("<scene version=\"3.0.0\">") +
          R"(<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="0"/></film></sensor>)" + kLight + "</scene>";
    load_error(xml);
}

TEST(SceneErrors, BadParameterValues) {
    load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><float name="radius" value="-1"/></shape>)"));
    load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><float name="radius" value="abc"/></shape>)"));
    load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><bsdf type="roughconductor"><string name="material" value="Unobtainium"/></bsdf></shape>)"));
    load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><bsdf type="dielectric"><string name="int_ior" value="glassy"/></bsdf></shape>)"));
    load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><ref id="nothing"/></shape>)"));
}

TEST(SceneErrors, PrincipledTakesEitherEtaOrSpecular) {
    std::string msg = load_error(scene_with(std::string(kLight) + R"(
<shape type="sphere"><bsdf type="principled"><float name="eta" value="1.4"/><float name="specular" value="0.3"/></bsdf></shape>)"));
    EXPECT_NE(msg.find(":4:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("either 'eta' or 'specular'"), std::string::npos) << msg;
    load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><bsdf type="principled"><float name="eta" value="-1"/></bsdf></shape>)"));
    load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><bsdf type="principled"><float name="main_specular_sampling_rate" value="0"/></bsdf></shape>)"));
}

// Mitsuba's rule for principled's lobes: a parameter left out, or given as the float 0, switches its lobe
// off; given (a texture, an rgb, a non-zero float) it is on. spec_trans decides whether the BSDF has a
// transmission lobe, and with it eta = 1 (or specular = 0) moves off 1 as Mitsuba does.
TEST(SceneLoader, PrincipledLobesFollowMitsubasPresenceRule) {
    auto load_bsdf = [](const std::string &params) {
        std::string path = write_temp_scene(scene_with(std::string(kLight) + "<shape type=\"sphere\"><bsdf type=\"principled\">" +
                                                       params + "</bsdf></shape>"));
        auto scene = load_scene(path);
        return std::dynamic_pointer_cast<const PrincipledBSDF>(scene->shapes().at(0)->bsdf);
    };
    auto opaque = load_bsdf(R"(<float name="spec_trans" value="0"/><float name="anisotropic" value="0"/>)");
    ASSERT_TRUE(opaque);
    EXPECT_FALSE(opaque->flags() & BSDFTransmission);
    EXPECT_FALSE(opaque->needs_tangents());
    EXPECT_FLOAT_EQ(opaque->eta(), 1.5f);  // specular 0.5
    auto glass = load_bsdf(R"(<float name="spec_trans" value="0.5"/><float name="eta" value="1"/><float name="anisotropic" value="0.3"/>)");
    EXPECT_TRUE(glass->flags() & BSDFGlossyTransmission);
    EXPECT_TRUE(glass->needs_tangents());
    EXPECT_FLOAT_EQ(glass->eta(), 1.001f);
    EXPECT_FLOAT_EQ(load_bsdf(R"(<float name="eta" value="1"/>)")->eta(), 1.f);
    auto textured = load_bsdf(R"(<texture name="spec_trans" type="checkerboard"/><float name="specular" value="0"/>)");
    EXPECT_TRUE(textured->flags() & BSDFGlossyTransmission);
    EXPECT_NEAR(textured->eta(), principled_eta_from_specular(1e-3f), 1e-6f);
}

TEST(SceneLoader, PrincipledThinLoadsWithItsLobes) {
    auto load_bsdf = [](const std::string &params) {
        std::string path = write_temp_scene(scene_with(std::string(kLight) + "<shape type=\"rectangle\"><bsdf type=\"principledthin\">" +
                                                       params + "</bsdf></shape>"));
        return load_scene(path)->shapes().at(0)->bsdf;
    };
    auto leaf = load_bsdf(R"(<texture name="base_color" type="checkerboard"/><float name="diff_trans" value="1.2"/>
        <float name="eta" value="1.3"/><float name="spec_trans" value="0"/>)");
    ASSERT_TRUE(std::dynamic_pointer_cast<const PrincipledThinBSDF>(leaf));
    EXPECT_TRUE(leaf->flags() & BSDFDiffuseTransmission);
    EXPECT_FALSE(leaf->flags() & BSDFGlossyTransmission);
    auto sheet = load_bsdf(R"(<float name="spec_trans" value="0.8"/><float name="anisotropic" value="0.2"/>)");
    EXPECT_TRUE(sheet->flags() & BSDFGlossyTransmission);
    EXPECT_FALSE(sheet->flags() & BSDFDiffuseTransmission);
    EXPECT_TRUE(sheet->needs_tangents());
    load_error(scene_with(std::string(kLight) + R"(<shape type="sphere"><bsdf type="principledthin"><float name="diffuse_reflectance_sampling_rate" value="0"/></bsdf></shape>)"));
}

// hair: Mitsuba's parameters (pigments by default, or sigma_a times scale; amber in air) reach the BSDF,
// which then evaluates as one built from the same values.
TEST(SceneLoader, HairLoadsMitsubasParameters) {
    auto load_bsdf = [](const std::string &params) {
        std::string path = write_temp_scene(scene_with(std::string(kLight) + "<shape type=\"cylinder\"><bsdf type=\"hair\">" +
                                                       params + "</bsdf></shape>"));
        return load_scene(path)->shapes().at(0)->bsdf;
    };
    auto expect_same = [](const BSDFPtr &loaded, HairParams p) {
        ASSERT_TRUE(std::dynamic_pointer_cast<const HairBSDF>(loaded));
        EXPECT_TRUE(loaded->needs_tangents());
        const HairBSDF built(p);
        SurfaceInteraction si;
        const BSDFContext ctx;
        for (const Vec3 &wi : {normalize(Vec3(0.3f, 0.4f, 0.8f)), normalize(Vec3(-0.5f, -0.2f, 0.3f))})
            for (const Vec3 &wo : {normalize(Vec3(-0.3f, -0.4f, 0.8f)), normalize(Vec3(0.2f, 0.1f, -0.9f))}) {
                const Color a = loaded->eval(ctx, si, wi, wo), b = built.eval(ctx, si, wi, wo);
                for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(a[c], b[c]);
                EXPECT_FLOAT_EQ(loaded->pdf(ctx, si, wi, wo), built.pdf(ctx, si, wi, wo));
            }
    };
    HairParams defaults;
    defaults.sigma_a = constant_texture(hair_pigment_absorption(1.3f, 0.2f));
    expect_same(load_bsdf(""), defaults);
    HairParams pigments = defaults;
    pigments.sigma_a = constant_texture(hair_pigment_absorption(0.01f, 1.6f));
    pigments.longitudinal_roughness = 0.2f, pigments.azimuthal_roughness = 0.6f, pigments.scale_tilt_deg = -3.f;
    pigments.eta = 1.333f / 1.000277f;  // water
    // A scale beside pigments is read, as Mitsuba reads it, and scales nothing.
    expect_same(load_bsdf(R"(<float name="eumelanin" value="0.01"/><float name="pheomelanin" value="1.6"/>
        <float name="longitudinal_roughness" value="0.2"/><float name="azimuthal_roughness" value="0.6"/>
        <float name="scale_tilt" value="-3"/><string name="int_ior" value="water"/><float name="scale" value="9"/>)"), pigments);
    HairParams absorption = defaults;
    absorption.sigma_a = constant_texture(Color(0.2f, 0.25f, 0.7f));
    absorption.sigma_a_scale = 200.f;
    absorption.eta = 1.6f / 1.2f;
    expect_same(load_bsdf(R"(<rgb name="sigma_a" value="0.2, 0.25, 0.7"/><float name="scale" value="200"/>
        <float name="int_ior" value="1.6"/><float name="ext_ior" value="1.2"/>)"), absorption);
}

TEST(SceneErrors, HairSaysWhatIsWrong) {
    auto hair_error = [](const std::string &params) {
        return load_error(scene_with(std::string(kLight) + "\n<shape type=\"cylinder\"><bsdf type=\"hair\">" + params +
                                     "</bsdf></shape>"));
    };
    std::string msg = hair_error(R"(<rgb name="sigma_a" value="0.2"/><float name="eumelanin" value="0.3"/>)");
    EXPECT_NE(msg.find(":4:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("either 'sigma_a' or the pigments"), std::string::npos) << msg;
    EXPECT_NE(hair_error(R"(<float name="longitudinal_roughness" value="0"/>)").find("(0, 1]"), std::string::npos);
    EXPECT_NE(hair_error(R"(<float name="azimuthal_roughness" value="2"/>)").find("azimuthal_roughness"), std::string::npos);
    EXPECT_NE(hair_error(R"(<float name="int_ior" value="1.2"/><float name="ext_ior" value="1.2"/>)").find("must differ"),
              std::string::npos);
    EXPECT_NE(hair_error(R"(<float name="pheomelanin" value="-1"/>)").find("non-negative"), std::string::npos);
}

// normalmap and blendbsdf: a missing normal map names its path, and each wrapper says what it lacks.
TEST(SceneErrors, NormalMapAndBlendSayWhatIsMissing) {
    std::string msg = load_error(scene_with(std::string(kLight) + R"(<shape type="rectangle"><bsdf type="normalmap">
        <texture name="normalmap" type="bitmap"><string name="filename" value="textures/no_normals.png"/><boolean name="raw" value="true"/></texture>
        <bsdf type="diffuse"/></bsdf></shape>)"));
    EXPECT_NE(msg.find("textures/no_normals.png"), std::string::npos) << msg;
    msg = load_error(scene_with(std::string(kLight) + R"(<shape type="rectangle"><bsdf type="normalmap"><bsdf type="diffuse"/></bsdf></shape>)"));
    EXPECT_NE(msg.find("'normalmap'"), std::string::npos) << msg;
    msg = load_error(scene_with(std::string(kLight) + R"(<shape type="rectangle"><bsdf type="normalmap"><rgb name="normalmap" value="0.5,0.5,1"/></bsdf></shape>)"));
    EXPECT_NE(msg.find("needs 1 nested <bsdf>, found 0"), std::string::npos) << msg;
    msg = load_error(scene_with(std::string(kLight) + R"(
<shape type="rectangle"><bsdf type="blendbsdf"><float name="weight" value="0.3"/><bsdf type="diffuse"/></bsdf></shape>)"));
    EXPECT_NE(msg.find(":4:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("needs 2 nested <bsdf>, found 1"), std::string::npos) << msg;
    msg = load_error(scene_with(std::string(kLight) + R"(<shape type="rectangle"><bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="conductor"/></bsdf></shape>)"));
    EXPECT_NE(msg.find("'weight'"), std::string::npos) << msg;
}

// Both load with their nested BSDFs, the blend's weight a float or a texture, and the normal map's flags.
TEST(SceneLoader, NormalMapAndBlendLoad) {
    auto load_bsdf = [](const std::string &bsdf) {
        return load_scene(write_temp_scene(scene_with(std::string(kLight) + "<shape type=\"rectangle\">" + bsdf + "</shape>")))
            ->shapes().at(0)->bsdf;
    };
    auto blend = load_bsdf(R"(<bsdf type="blendbsdf"><float name="weight" value="0.3"/><bsdf type="diffuse"/>
        <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf></bsdf>)");
    ASSERT_TRUE(std::dynamic_pointer_cast<const BlendBSDF>(blend));
    EXPECT_EQ(blend->flags(), uint32_t(BSDFDiffuseReflection | BSDFGlossyReflection));
    auto textured = load_bsdf(R"(<bsdf type="blendbsdf"><texture name="weight" type="checkerboard"/><bsdf type="diffuse"/>
        <bsdf type="twosided"><bsdf type="conductor"/></bsdf></bsdf>)");
    EXPECT_EQ(textured->flags(), uint32_t(BSDFDiffuseReflection | BSDFDeltaReflection));
    auto normals = load_bsdf(R"(<bsdf type="normalmap"><rgb name="normalmap" value="0.6,0.5,0.9"/>
        <boolean name="flip_invalid_normals" value="false"/><boolean name="use_shadowing_function" value="false"/>
        <bsdf type="roughplastic"/></bsdf>)");
    ASSERT_TRUE(std::dynamic_pointer_cast<const NormalMapBSDF>(normals));
    EXPECT_TRUE(normals->needs_tangents());
    EXPECT_TRUE(normals->flags() & BSDFGlossyReflection);
}

// Mitsuba's default BSDF is diffuse 0.5, except on an emitter, where it is black: a light without a BSDF
// reflects nothing.
TEST(SceneLoader, DefaultBsdfIsBlackOnEmitters) {
    std::string path = write_temp_scene(scene_with(R"(
<shape type="rectangle"><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
<shape type="sphere"/>)"));
    auto scene = load_scene(path);
    SurfaceInteraction si;
    const Vec3 up(0.f, 0.f, 1.f);
    const BSDFContext ctx;
    EXPECT_TRUE(is_black(scene->shapes().at(0)->bsdf->eval(ctx, si, up, up)));
    EXPECT_NEAR(scene->shapes().at(1)->bsdf->eval(ctx, si, up, up).x, 0.5f * kInvPi, 1e-6f);
}

TEST(SceneErrors, UnknownIntegratorAndOptionsAreRejected) {
    EXPECT_THROW(make_integrator("bidir-magic", Options()), std::invalid_argument);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"max_dpeth", "3"}})), std::invalid_argument);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"max_depth", "three"}})), std::invalid_argument);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"max_depth", "0"}})), std::invalid_argument);
}

TEST(SceneLoader, DemoSceneLoads) {
    auto scene = load_scene(std::string(NEEPP_SOURCE_DIR) + "/scenes/door-ajar/scene.xml");
    EXPECT_EQ(scene->lights().size(), 1u);
    EXPECT_GT(scene->triangle_count(), 100u);
    EXPECT_EQ(scene->camera.width, 480);
    EXPECT_EQ(scene->settings.integrator, "path");
    EXPECT_EQ(scene->settings.integrator_options.at("max_depth"), "12");
    auto small = load_scene(std::string(NEEPP_SOURCE_DIR) + "/scenes/door-ajar/scene.xml", {{"resx", "64"}, {"resy", "32"}});
    EXPECT_EQ(small->camera.width, 64);
    EXPECT_EQ(small->camera.height, 32);
}

}  // namespace

// neepp check: one run lists every problem, each at its line, where loading stops at the first.
TEST(SceneCheck, ListsEveryProblemAtOnce) {
    const std::string xml = scene_with(  // the camera is line 2
        "<bsdf type=\"velvet\" id=\"unused\"/>\n"                                              // 3
        "<shape type=\"obj\"><string name=\"filename\" value=\"no-such-mesh.obj\"/></shape>\n"  // 4
        "<shape type=\"sphere\">\n"                                                           // 5
        "  <float name=\"radiuss\" value=\"2\"/>\n"                                            // 6
        "  <bsdf type=\"glitter\"/>\n"                                                        // 7
        "</shape>\n"                                                                          // 8
        "<shape type=\"teapot\"/>\n"                                                          // 9
        "<medium type=\"homogeneous\" id=\"fog\"><phase type=\"fogbow\"/></medium>\n");      // 10
    const std::string path = write_temp_scene(xml, "many_problems.xml");
    const std::vector<SceneProblem> problems = check_scene(path);
    std::vector<std::pair<int, bool>> where;
    for (const SceneProblem &p : problems) {
        EXPECT_EQ(p.file, path);
        where.push_back({p.line, p.error});
    }
    const std::vector<std::pair<int, bool>> expected = {{3, true}, {4, true}, {7, true}, {5, false}, {9, true}, {10, true},
                                                        {0, true}};
    EXPECT_EQ(where, expected);
    EXPECT_NE(problems[1].problem.find("no-such-mesh.obj"), std::string::npos);
    EXPECT_NE(problems[3].problem.find("radiuss"), std::string::npos);
    EXPECT_NE(problems[5].problem.find("unsupported phase function 'fogbow'"), std::string::npos);
    EXPECT_NE(problems[6].problem.find("no light source"), std::string::npos);
    EXPECT_EQ(problems[0].text().rfind(path + ":3: error: ", 0), 0u) << problems[0].text();
    EXPECT_NE(load_error(xml, "many_problems.xml").find("many_problems.xml:4:"), std::string::npos);  // render: the first
}

// A broken element that several others refer to is listed once, at its own line.
TEST(SceneCheck, ListsASharedBrokenElementOnce) {
    const std::string xml = scene_with(std::string(kLight) + "\n" +  // the light is line 3
        "<medium type=\"heterogeneous\" id=\"m\"><volume name=\"sigma_t\" type=\"gridvolume\">"
        "<string name=\"filename\" value=\"absent.vol\"/></volume></medium>\n"                         // 4
        "<shape type=\"cube\"><bsdf type=\"null\"/><ref id=\"m\" name=\"interior\"/></shape>\n"       // 5
        "<shape type=\"sphere\"><bsdf type=\"null\"/><ref id=\"m\" name=\"interior\"/></shape>\n");   // 6
    const std::vector<SceneProblem> problems = check_scene(write_temp_scene(xml, "shared.xml"));
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(problems[0].line, 4);
    EXPECT_NE(problems[0].problem.find("absent.vol"), std::string::npos) << problems[0].problem;
}

TEST(SceneCheck, ASoundSceneHasNoProblem) {
    const std::string path = write_temp_scene(scene_with(std::string(kLight) + "\n<shape type=\"sphere\"/>"), "sound.xml");
    EXPECT_TRUE(check_scene(path).empty());
}

// An area emitter declared at the top level and <ref>'d by shapes lights each of them (Mitsuba's form);
// one that no shape uses is an error at its line, not a light silently dropped.
TEST(SceneLoader, TopLevelAreaEmittersLightTheShapesThatReferenceThem) {
    const std::string lights = "<emitter type=\"area\" id=\"glow\"><rgb name=\"radiance\" value=\"4\"/></emitter>\n";
    auto path = write_temp_scene(scene_with(lights + "<shape type=\"sphere\"><ref id=\"glow\"/></shape>\n"
                                                     "<shape type=\"rectangle\"><ref id=\"glow\"/></shape>"), "ref_area.xml");
    auto scene = load_scene(path);
    ASSERT_EQ(scene->lights().size(), 2u);
    EXPECT_EQ(scene->shapes()[0]->area_light, scene->lights()[0].get());
    const std::string msg = load_error(scene_with(std::string(kLight) + "\n" + lights + "<shape type=\"sphere\"/>"), "unref.xml");
    EXPECT_NE(msg.find("unref.xml:4:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("attached to no shape"), std::string::npos) << msg;
}

// A -D parameter the scene never substitutes is refused, naming it, as Mitsuba 3 refuses it ("unused
// parameters"); a <default> alone does not use one, and a caller's own value (the CLI's --spp) may go unused.
TEST(SceneErrors, UnusedDefinesAreRefused) {
    const std::string path = write_temp_scene(
        scene_with(std::string(kLight) + "\n<default name=\"r\" value=\"1\"/>\n<default name=\"unread\" value=\"1\"/>\n"
                   "<shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>"),
        "defines.xml");
    EXPECT_NO_THROW(load_scene(path, {{"r", "2"}}));
    try {
        load_scene(path, {{"r", "2"}, {"unread", "3"}, {"speling", "4"}});
        ADD_FAILURE() << "unused defines were accepted";
    } catch (const SceneError &e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("defines.xml"), std::string::npos) << msg;
        EXPECT_NE(msg.find("-D speling=4, -D unread=3"), std::string::npos) << msg;
        EXPECT_EQ(msg.find("r=2"), std::string::npos) << msg;
    }
    EXPECT_NO_THROW(load_scene(path, {{"r", "2"}, {"spp", "8"}}, {"spp"}));
    const std::vector<SceneProblem> problems = check_scene(path, {{"speling", "4"}});
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_TRUE(problems[0].error);
    EXPECT_NE(problems[0].problem.find("speling"), std::string::npos);
}

// The orthographic sensor loads with its clip distances and crop; bdpt and light tracing refuse it.
TEST(SceneLoader, OrthographicSensorLoads) {
    const std::string xml = std::string("<scene version=\"3.0.0\">\n") +
                            "<sensor type=\"orthographic\"><float name=\"near_clip\" value=\"0.5\"/>"
                            "<transform name=\"to_world\"><scale value=\"3\"/></transform>"
                            "<film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"4\"/>"
                            "<integer name=\"crop_width\" value=\"4\"/></film></sensor>\n" +
                            kLight + "\n<shape type=\"sphere\"/>\n</scene>\n";
    auto scene = load_scene(write_temp_scene(xml, "ortho.xml"));
    EXPECT_EQ(scene->camera.projection, Projection::Orthographic);
    EXPECT_EQ(scene->camera.width, 4);
    EXPECT_EQ(scene->camera.film_width, 8);
    const Ray r = scene->camera.generate_ray(Vec2(0.5f, 0.5f));  // the crop's centre: a quarter of the film
    EXPECT_NEAR(r.o.x, 1.5f, 1e-5f);                             // camera x 0.5, scaled by 3
    EXPECT_NEAR(r.o.z, 1.5f, 1e-5f);                             // the near plane, scaled too
    EXPECT_NE(load_error(std::string("<scene version=\"3.0.0\">\n<sensor type=\"orthographic\">"
                                     "<float name=\"near_clip\" value=\"0\"/></sensor>\n") +
                             kLight + "\n</scene>\n")
                  .find("near_clip must be greater than zero"),
              std::string::npos);
    const std::string ortho_path = write_temp_scene(xml, "ortho_bdpt.xml");
    for (const char *integrator : {"bdpt", "light"}) {
        try {
            render_scene_file(ortho_path, 1, 1, Options{}, integrator);
            ADD_FAILURE() << integrator << " rendered an orthographic sensor";
        } catch (const std::invalid_argument &e) {
            EXPECT_NE(std::string(e.what()).find("orthographic"), std::string::npos) << e.what();
        }
    }
}

// A <sampler> at the top level is made (so a bad one is an error) and used only where a sensor <ref>s it,
// as in Mitsuba 3; alone it leaves the sensor's own (or the default) sampler in place.
TEST(SceneLoader, TopLevelSamplerIsUsedOnlyThroughRefs) {
    const std::string sampler = R"(<sampler type="stratified" id="s"><integer name="sample_count" value="9"/></sampler>)";
    const std::string referenced = std::string("<scene version=\"3.0.0\">\n") + sampler +
                                   "\n<sensor type=\"perspective\"><ref id=\"s\"/></sensor>\n" + kLight + "\n</scene>\n";
    auto scene = load_scene(write_temp_scene(referenced, "sampler_ref.xml"));
    EXPECT_EQ(scene->settings.sampler, "stratified");
    EXPECT_EQ(scene->settings.spp, 9);
    const std::string alone = std::string("<scene version=\"3.0.0\">\n") + sampler + "\n" + kCamera + "\n" + kLight + "\n</scene>\n";
    scene = load_scene(write_temp_scene(alone, "sampler_alone.xml"));
    EXPECT_EQ(scene->settings.sampler, "independent");
    EXPECT_EQ(scene->settings.spp, RenderSettings{}.spp);  // the sensor's own default
    const std::string msg = load_error(scene_with(R"(<sampler type="halton"/>)"), "bad_sampler.xml");
    EXPECT_NE(msg.find("bad_sampler.xml:3:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("unsupported sampler 'halton'"), std::string::npos) << msg;
    EXPECT_NE(load_error(scene_with(R"(<sampler type="independent"><integer name="sample_count" value="0"/></sampler>)"))
                  .find("sample_count must be at least 1"),
              std::string::npos);
}

// The thinlens sensor: its lens and focus distance load, its errors are Mitsuba's (a radius is required, a
// scaling to_world is refused), and bdpt and light tracing refuse it with a clear message.
TEST(SceneLoader, ThinLensSensorLoads) {
    auto sensor = [](const std::string &props) {
        return std::string("<scene version=\"3.0.0\">\n<sensor type=\"thinlens\"><float name=\"fov\" value=\"40\"/>") +
               props + "<film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film></sensor>\n" +
               kLight + "\n<shape type=\"sphere\"/>\n</scene>\n";
    };
    const std::string xml = sensor(R"(<float name="aperture_radius" value="0.25"/><float name="focus_distance" value="3"/>
        <transform name="to_world"><lookat origin="0,0,-5" target="0,0,0" up="0,1,0"/></transform>)");
    auto scene = load_scene(write_temp_scene(xml, "thinlens.xml"));
    EXPECT_TRUE(scene->camera.has_lens());
    EXPECT_FLOAT_EQ(scene->camera.aperture_radius, 0.25f);
    EXPECT_FLOAT_EQ(scene->camera.focus_distance, 3.f);
    EXPECT_FALSE(scene->camera.has_importance());
    scene = load_scene(write_temp_scene(sensor(R"(<float name="aperture_radius" value="0.1"/>)"), "thinlens_far.xml"));
    EXPECT_FLOAT_EQ(scene->camera.focus_distance, 1e4f);  // Mitsuba's default: the far clip distance
    EXPECT_NE(load_error(sensor("")).find("aperture_radius"), std::string::npos);
    EXPECT_NE(load_error(sensor(R"(<float name="aperture_radius" value="0.1"/><transform name="to_world"><scale value="2"/></transform>)"))
                  .find("must not scale"),
              std::string::npos);
    EXPECT_NE(load_error(sensor(R"(<float name="aperture_radius" value="0.1"/><float name="focus_distance" value="-1"/>)"))
                  .find("focus_distance must be greater than zero"),
              std::string::npos);
    const std::string path = write_temp_scene(xml, "thinlens_bdpt.xml");
    for (const char *integrator : {"bdpt", "light"}) {
        try {
            render_scene_file(path, 1, 1, Options{}, integrator);
            ADD_FAILURE() << integrator << " rendered a thinlens sensor";
        } catch (const std::invalid_argument &e) {
            EXPECT_NE(std::string(e.what()).find("thinlens"), std::string::npos) << e.what();
        }
    }
}

// Media: a shape names its medium interior or exterior, one of each; a medium has one phase function of a
// kind the loader knows; a volume-valued coefficient is not supported yet: each an error at its line.
TEST(SceneErrors, MediaMistakesNameTheirLine) {
    const std::string fog = R"(<medium type="homogeneous" id="fog"/>)";
    auto shape = [&](const std::string &body) { return scene_with(fog + "\n<shape type=\"sphere\">\n" + body + "\n</shape>\n" + kLight); };
    EXPECT_NE(load_error(shape(R"(<ref id="fog" name="inside"/>)")).find("\"interior\" or its \"exterior\""), std::string::npos);
    EXPECT_NE(load_error(shape(R"(<ref id="fog" name="interior"/><ref id="fog" name="interior"/>)")).find("\"interior\" is specified more than once"),
              std::string::npos);
    EXPECT_NE(load_error(scene_with(R"(<medium type="homogeneous"><phase type="rayleighx"/></medium>)" + std::string(kLight)))
                  .find("unsupported phase function 'rayleighx'"), std::string::npos);
    EXPECT_NE(load_error(scene_with(R"(<medium type="homogeneous"><phase type="hg"/><phase type="isotropic"/></medium>)" +
                                    std::string(kLight))).find("one phase function"), std::string::npos);
    EXPECT_NE(load_error(scene_with(R"(<medium type="homogeneous"><volume type="gridvolume" name="albedo"/></medium>)" +
                                    std::string(kLight))).find("volume"), std::string::npos);
    // The camera sits in one medium.
    const std::string two = R"(<scene version="3.0.0"><sensor type="perspective"><medium type="homogeneous"/><medium type="homogeneous"/>
      <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>)" + std::string(kLight) + "</scene>";
    EXPECT_NE(load_error(two).find("one medium"), std::string::npos);
    // A medium that fills nothing loads, as in Mitsuba, with a warning at its line; the scene has no media.
    const std::string idle = write_temp_scene(scene_with("<shape type=\"sphere\"/>\n<medium type=\"homogeneous\" id=\"idle\"/>\n" +
                                                         std::string(kLight)), "idle.xml");
    const std::vector<SceneProblem> problems = check_scene(idle);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_FALSE(problems[0].error);
    EXPECT_EQ(problems[0].line, 4);
    EXPECT_NE(problems[0].problem.find("fills nothing"), std::string::npos) << problems[0].problem;
    EXPECT_FALSE(load_scene(idle)->has_media());
    // What loads: the medium reaches the shape and the camera.
    auto scene = load_scene(write_temp_scene(R"(<scene version="3.0.0"><medium type="homogeneous" id="fog"/>
      <sensor type="perspective"><ref id="fog"/><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
      <shape type="sphere"><ref id="fog" name="exterior"/><medium type="homogeneous" name="interior"><float name="sigma_t" value="2"/></medium></shape>)" +
                                             std::string(kLight) + "</scene>"));
    ASSERT_TRUE(scene->has_media());
    EXPECT_EQ(scene->camera.medium, scene->shapes()[0]->exterior);
    ASSERT_NE(scene->shapes()[0]->interior, nullptr);
    EXPECT_NE(scene->shapes()[0]->interior, scene->shapes()[0]->exterior);
    EXPECT_EQ(scene->shapes()[0]->interior->majorant(Vec3(0, 0, 1)), Color(2.f));
}

// rayleigh, tabphase and blendphase: what loads (a blend's nested phase functions in order, its weight a
// number or a volume), and each mistake an error at its line that says what was expected.
TEST(SceneErrors, PhaseFunctionsLoadAndTheirMistakesNameTheirLine) {
    auto in_medium = [](const std::string &phase) {
        return scene_with("<shape type=\"sphere\"><bsdf type=\"null\"/><medium type=\"homogeneous\" name=\"interior\">\n" + phase +
                          "\n</medium></shape>\n" + kLight);
    };
    auto phase_of = [&](const std::string &phase) { return load_scene(write_temp_scene(in_medium(phase)))->shapes()[0]->interior->phase; };
    EXPECT_TRUE(std::dynamic_pointer_cast<const RayleighPhase>(phase_of(R"(<phase type="rayleigh"/>)")));
    const auto tab = std::dynamic_pointer_cast<const TabulatedPhase>(phase_of(R"(<phase type="tabphase"><string name="values" value="1, 3"/></phase>)"));
    ASSERT_TRUE(tab);
    const Vec3 wi(0, 0, 1);
    EXPECT_FLOAT_EQ(tab->eval(Vec3(0.f), wi, -wi), 3.f / 4.f * kInv2Pi);  // the last value is forward
    const auto blend = std::dynamic_pointer_cast<const BlendPhase>(phase_of(
        R"(<phase type="blendphase"><float name="weight" value="0.25"/><phase type="isotropic"/><phase type="rayleigh"/></phase>)"));
    ASSERT_TRUE(blend);
    EXPECT_FLOAT_EQ(blend->weight(Vec3(0.f)), 0.25f);
    // w = 0.25 of rayleigh's 3/(8 pi) straight back, 0.75 of the isotropic 1/(4 pi).
    EXPECT_NEAR(blend->eval(Vec3(0.f), wi, wi), 0.75f * kInv4Pi + 0.25f * 3.f / (8.f * kPi), 1e-6f);
    const auto volume_weight = std::dynamic_pointer_cast<const BlendPhase>(phase_of(
        R"(<phase type="blendphase"><phase type="isotropic"/><phase type="rayleigh"/><volume name="weight" type="constvolume"><float name="value" value="0.5"/></volume></phase>)"));
    ASSERT_TRUE(volume_weight);
    EXPECT_FLOAT_EQ(volume_weight->weight(Vec3(0.3f)), 0.5f);

    // The phase function is on the scene's line 4.
    const std::vector<std::pair<std::string, std::string>> mistakes = {
        {R"(<phase type="tabphase"/>)", "needs its 'values'"},
        {R"(<phase type="tabphase"><string name="values" value="1"/></phase>)", "at least two numbers"},
        {R"(<phase type="tabphase"><string name="values" value="0, 0, 0"/></phase>)", "all zero"},
        {R"(<phase type="tabphase"><string name="values" value="1, -2"/></phase>)", "\"-2\" is negative"},
        {R"(<phase type="tabphase"><string name="values" value="1, inf"/></phase>)", "\"inf\" is not a finite number"},
        {R"(<phase type="tabphase"><string name="values" value="1, 2a"/></phase>)", "\"2a\" is not a number"},
        {R"(<phase type="blendphase"><phase type="isotropic"/><float name="weight" value="0.5"/></phase>)", "two nested <phase> (found 1)"},
        {R"(<phase type="blendphase"><phase type="isotropic"/><phase type="isotropic"/><phase type="hg"/><float name="weight" value="0.5"/></phase>)",
         "this is a third"},
        {R"(<phase type="blendphase"><phase type="isotropic"/><phase type="isotropic"/></phase>)", "needs its 'weight'"},
        {R"(<phase type="blendphase"><phase type="isotropic"/><phase type="sggxx"/><float name="weight" value="0.5"/></phase>)",
         "unsupported phase function 'sggxx'"},
        {R"(<phase type="blendphase"><phase type="isotropic"/><phase type="isotropic"/><texture name="weight" type="checkerboard"/></phase>)",
         "not a <texture>"},
        {R"(<phase type="blendphase"><phase type="isotropic"/><phase type="isotropic"/><volume name="weights" type="constvolume"/></phase>)",
         "a blendphase's volume is its \"weight\", not \"weights\""},
    };
    for (const auto &[phase, needle] : mistakes) {
        const std::string msg = load_error(in_medium(phase));
        EXPECT_NE(msg.find(".xml:4:"), std::string::npos) << phase << ": " << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << phase << ": " << msg;
    }
}

// sggx: S from a constvolume of six numbers (neepp's) makes the phase function and scales the medium's
// extinction by the projected area; each mistake is an error at its line (a 6-channel grid's are in
// test_grid_volume_errors.cpp).
TEST(SceneErrors, SggxLoadsItsSAndItsMistakesNameTheirLine) {
    auto in_medium = [](const std::string &phase, const std::string &type = "homogeneous") {
        return scene_with("<shape type=\"sphere\"><bsdf type=\"null\"/><medium type=\"" + type +
                          "\" name=\"interior\"><float name=\"sigma_t\" value=\"2\"/>\n" + phase + "\n</medium></shape>\n" + kLight);
    };
    const auto scene = load_scene(write_temp_scene(in_medium(
        R"(<phase type="sggx"><volume name="S" type="constvolume"><string name="value" value="1, 0.25, 0.04, 0, 0, 0"/></volume></phase>)")));
    const Medium &m = *scene->shapes()[0]->interior;
    const auto sggx = std::dynamic_pointer_cast<const SGGXPhase>(m.phase);
    ASSERT_TRUE(sggx);
    EXPECT_FLOAT_EQ(sggx->projected_area(Vec3(0.f), Vec3(0, 1, 0)), 0.5f);
    EXPECT_FLOAT_EQ(m.majorant(Vec3(0, 1, 0)).x, 1.f);   // 2 x sqrt(0.25)
    EXPECT_FLOAT_EQ(m.majorant(Vec3(0, 0, -1)).y, 0.4f);  // 2 x sqrt(0.04)
    EXPECT_TRUE(m.homogeneous());
    // In a heterogeneous medium the majorant bounds every direction: sqrt of S's largest eigenvalue.
    const auto het = load_scene(write_temp_scene(in_medium(
        R"(<phase type="sggx"><volume name="S" type="constvolume"><string name="value" value="4, 1, 1, 0, 0, 0"/></volume></phase>)",
        "heterogeneous")));
    EXPECT_FLOAT_EQ(het->shapes()[0]->interior->majorant(Vec3(0, 1, 0)).x, 4.f);

    // The phase function is on the scene's line 4.
    const std::vector<std::pair<std::string, std::string>> mistakes = {
        {R"(<phase type="sggx"/>)", "an sggx needs its 'S'"},
        {R"(<phase type="sggx"><volume name="s" type="constvolume"><string name="value" value="1 1 1 0 0 0"/></volume></phase>)",
         "an sggx holds one <volume> named \"S\""},
        {R"(<phase type="sggx"><volume name="S" type="constvolume"><rgb name="value" value="1"/></volume></phase>)",
         "an sggx's S is a symmetric matrix: a string of six numbers"},
        {R"(<phase type="sggx"><volume name="S" type="constvolume"><string name="value" value="1 1 1 0 0"/></volume></phase>)",
         "six numbers S_xx, S_yy, S_zz, S_xy, S_xz, S_yz (found 5)"},
        {R"(<phase type="sggx"><volume name="S" type="constvolume"><string name="value" value="1 1 1 0 x 0"/></volume></phase>)",
         "\"x\" is not a number"},
        {R"(<phase type="sggx"><volume name="S" type="constvolume"><string name="value" value="1 1 1 2 0 0"/></volume></phase>)",
         "not positive semi-definite"},
        {R"(<phase type="blendphase"><phase type="isotropic"/><phase type="isotropic"/><volume name="weight" type="constvolume"><string name="value" value="1 1 1 0 0 0"/></volume></phase>)",
         "six numbers are a symmetric matrix (an sggx's S), not a blendphase's weight"},
    };
    for (const auto &[phase, needle] : mistakes) {
        const std::string msg = load_error(in_medium(phase));
        EXPECT_NE(msg.find(".xml:4:"), std::string::npos) << phase << ": " << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << phase << ": " << msg;
    }
}
