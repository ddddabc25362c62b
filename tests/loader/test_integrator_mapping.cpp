// Scenes written for Mitsuba 3 name its integrators: each maps to the one here that renders the same
// image, keeping the options that shape it (a moment wrapper used to leave its nested max_depth behind,
// and the render silently used -1).
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
        {R"(<integrator type="volpath"><integer name="rr_depth" value="3"/></integrator>)", "path", {{"rr_depth", "3"}}},
        {R"(<integrator type="volpathmis"/>)", "path", {}},
        {R"(<integrator type="direct"><integer name="emitter_samples" value="4"/>
            <boolean name="hide_emitters" value="true"/></integrator>)",
         "path", {{"max_depth", "2"}, {"hide_emitters", "true"}}},
        {R"(<integrator type="ptracer"><integer name="max_depth" value="6"/><integer name="samples_per_pass" value="4"/></integrator>)",
         "light", {{"max_depth", "6"}}},
        {R"(<integrator type="moment"><integrator type="path"><integer name="max_depth" value="4"/></integrator></integrator>)",
         "path", {{"max_depth", "4"}}},
        {R"(<integrator type="moment"><integrator type="direct"/></integrator>)", "path", {{"max_depth", "2"}}},
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

TEST(IntegratorMapping, AWrapperWithoutOneNestedIntegratorIsAnError) {
    EXPECT_THROW(settings_of(R"(<integrator type="moment"/>)"), std::runtime_error);
    EXPECT_THROW(settings_of(R"(<integrator type="moment"><integrator type="path"/><integrator type="path"/></integrator>)"),
                 std::runtime_error);
}

}  // namespace
