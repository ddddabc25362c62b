// Scenes written for Mitsuba 3 name its integrators: each maps to the one here that renders the same
// image, keeping the options that shape it (a moment wrapper used to leave its nested max_depth behind,
// and the render silently used -1); moment and aov render as the first integrator they nest.
#include <gtest/gtest.h>
#include "neepp/loader/scene_loader.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

RenderSettings settings_of(const std::string &integrator_xml) {
    const std::string path = write_temp_scene(R"(<scene version="3.0.0">
  )" + integrator_xml + R"(
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,3" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
  <shape type="sphere"><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
</scene>)");
    return load_scene(path)->settings;
}

TEST(IntegratorMapping, MitsubasIntegratorsRenderAsTheirEquivalent) {
    struct Case {
        const char *xml, *integrator;
        std::map<std::string, std::string> options;
    };
    const std::vector<Case> cases = {
        {R"(<integrator type="path"><integer name="max_depth" value="5"/></integrator>)", "path", {{"max_depth", "5"}}},
        {R"(<integrator type="prb"><integer name="max_depth" value="7"/></integrator>)", "path", {{"max_depth", "7"}}},
        {R"(<integrator type="prb_basic"/>)", "path", {}},
        {R"(<integrator type="volpath"><integer name="rr_depth" value="3"/></integrator>)", "volpath", {{"rr_depth", "3"}}},
        {R"(<integrator type="volpathmis"/>)", "volpath", {}},
        {R"(<integrator type="prb_projective"><integer name="max_depth" value="4"/><integer name="sppi" value="0"/>
            <string name="guiding" value="grid"/></integrator>)", "path", {{"max_depth", "4"}}},
        {R"(<integrator type="direct_projective"><integer name="sppc" value="16"/><boolean name="guiding_proj" value="false"/>
            </integrator>)", "path", {{"max_depth", "2"}}},
        {R"(<integrator type="direct"><integer name="emitter_samples" value="4"/>
            <boolean name="hide_emitters" value="true"/></integrator>)",
         "path", {{"max_depth", "2"}, {"hide_emitters", "true"}}},
        {R"(<integrator type="ptracer"><integer name="max_depth" value="6"/><integer name="samples_per_pass" value="4"/></integrator>)",
         "light", {{"max_depth", "6"}}},
        {R"(<integrator type="moment"><integrator type="path"><integer name="max_depth" value="4"/></integrator></integrator>)",
         "path", {{"max_depth", "4"}}},
        {R"(<integrator type="moment"><integrator type="direct"/></integrator>)", "path", {{"max_depth", "2"}}},
        // aov's image is its first nested integrator's (Mitsuba's RGB channels), through other wrappers too.
        {R"(<integrator type="aov"><string name="aovs" value="dd.y:depth, nn:sh_normal"/>
            <integrator type="path" name="image"><integer name="max_depth" value="3"/></integrator></integrator>)",
         "path", {{"max_depth", "3"}}},
        {R"(<integrator type="aov"><string name="aovs" value="d:depth"/><integrator type="volpath" name="a">
            <integer name="rr_depth" value="2"/></integrator><integrator type="direct" name="b"/></integrator>)",
         "volpath", {{"rr_depth", "2"}}},
        {R"(<integrator type="aov"><string name="aovs" value="d:depth"/>
            <integrator type="moment"><integrator type="direct"/></integrator></integrator>)",
         "path", {{"max_depth", "2"}}},
        {R"(<integrator type="moment"><integrator type="path" name="first"/><integrator type="direct"/></integrator>)",
         "path", {}},
        {R"(<integrator type="bdpt"><string name="light_paths" value="neepp"/></integrator>)", "bdpt",
         {{"light_paths", "neepp"}}},
    };
    for (const Case &c : cases) {
        SCOPED_TRACE(c.xml);
        const RenderSettings s = settings_of(c.xml);
        EXPECT_EQ(s.integrator, c.integrator);
        EXPECT_EQ(s.integrator_options, c.options);
    }
}

// The load error's text, or "" when the scene loads.
std::string error_of(const std::string &integrator_xml) {
    try {
        settings_of(integrator_xml);
    } catch (const std::exception &e) {
        return e.what();
    }
    return "";
}

// Without a nested integrator Mitsuba's moment and aov render a black image (the AOV channels aside, which
// neepp does not write): refused, saying so. What Mitsuba refuses in an aov integrator is refused too.
TEST(IntegratorMapping, WhatMitsubaRendersBlackOrRefusesIsAnError) {
    const auto expect_error = [](const std::string &xml, const std::string &says) {
        const std::string e = error_of(xml);
        EXPECT_NE(e.find(says), std::string::npos) << xml << ": " << (e.empty() ? "loads" : e);
    };
    expect_error(R"(<integrator type="moment"/>)", "nests no integrator: Mitsuba's image is then black");
    expect_error(R"(<integrator type="aov"><string name="aovs" value="dd.y:depth"/></integrator>)",
                 "nests no integrator: Mitsuba's image is then black, beside the AOV channels");
    expect_error(R"(<integrator type="aov"><integrator type="path"/></integrator>)", "needs its string 'aovs'");
    expect_error(R"(<integrator type="aov"><string name="aovs" value="dd:depth,n:normal"/><integrator type="path"/></integrator>)",
                 "unknown AOV type 'normal' in 'n:normal'");
    expect_error(R"(<integrator type="aov"><string name="aovs" value="depth"/><integrator type="path"/></integrator>)",
                 "'depth' is not a name:type pair");
    expect_error(R"(<integrator type="aov"><string name="aovs" value="d:depth"/><integrator type="ptracer"/></integrator>)",
                 "sampling integrators only, not 'ptracer'");
    expect_error(R"(<integrator type="aovs"><integrator type="path"/></integrator>)", "unsupported integrator 'aovs'");
    EXPECT_EQ(error_of(R"(<integrator type="aov"><string name="aovs" value=" a:albedo  b:uv,c:shape_index, "/>
                          <integrator type="path"/></integrator>)"), "");
}

}  // namespace
