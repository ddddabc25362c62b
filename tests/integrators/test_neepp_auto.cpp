// -I neepp=auto: its options, its pilot's report, and that whichever candidate it renders with (forced
// through a saved state, as a resumed or distributed render forces it) gives plain NEE's image.
#include <gtest/gtest.h>
#include <algorithm>
#include "neepp/integrators/neepp_auto.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// Two area lights, one behind a wall, and a sky seen past it.
const char *kCourtXml = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,1.2,3" target="0,0.6,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.05" y="1"/><rotate y="1" angle="90"/><translate y="1"/></transform><ref id="white"/></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="0.6" y="0.3"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="90"/><translate x="-1" y="1.8"/></transform>
    <emitter type="area"><rgb name="radiance" value="6"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="90"/><translate x="1" y="1.8"/></transform>
    <emitter type="area"><rgb name="radiance" value="4"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.3"/></emitter>
</scene>)";

std::unique_ptr<Integrator> make(const OptionMap &o) { return make_integrator("path", Options(o)); }

TEST(NeeppAuto, RefusesTheOptionsItChoosesAndUnknownModes) {
    for (const char *key : {"light_sampler", "within_light", "shadow_rays"}) {
        try {
            make({{"neepp", "auto"}, {key, "nee"}});
            ADD_FAILURE() << key << " with neepp=auto was accepted";
        } catch (const std::invalid_argument &e) {
            EXPECT_NE(std::string(e.what()).find("neepp=auto chooses"), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(make({{"neepp", "maybe"}}), std::invalid_argument);
    EXPECT_THROW(make({{"neepp", "auto"}, {"bogus", "1"}}), std::invalid_argument);  // still reported as unused
    // Options only some candidates read (the map's) are not unused.
    EXPECT_NO_THROW(make({{"neepp", "auto"}, {"voxels", "8"}, {"q_min", "0.05"}, {"max_depth", "3"}}));
    EXPECT_NO_THROW(make({{"neepp", "off"}}));
}

TEST(NeeppAuto, PilotsEveryCandidateThatAppliesAndPicksByItsRule) {
    auto scene = load_scene(write_temp_scene(kCourtXml));
    auto integrator = make({{"neepp", "auto"}, {"max_depth", "4"}});
    auto &auto_integrator = dynamic_cast<AutoIntegrator &>(*integrator);
    auto_integrator.prepare(*scene);
    const auto &pilot = auto_integrator.pilot();
    ASSERT_EQ(pilot.size(), auto_candidates().size());  // several lights: all apply
    EXPECT_EQ(pilot.front().name, "nee");
    EXPECT_DOUBLE_EQ(pilot.front().efficiency, 1.0);
    const AutoPilotResult *best = nullptr;
    for (const AutoPilotResult &r : pilot) {
        EXPECT_GT(r.relative_variance, 0) << r.name;
        EXPECT_GT(r.seconds_per_sample, 0) << r.name;
        if (r.name != "nee" && (!best || r.efficiency > best->efficiency)) best = &r;
    }
    const std::string expected = best->efficiency > AutoIntegrator::kMargin ? best->name : "nee";
    EXPECT_EQ(auto_integrator.picked(), expected);
    const nlohmann::json stats = auto_integrator.statistics();
    EXPECT_EQ(stats["neepp_auto"]["picked"], expected);
    EXPECT_EQ(stats["neepp_auto"]["pilot"].size(), pilot.size());

    // One light: nothing to choose between, no pilot, plain NEE.
    auto room = load_scene(write_temp_scene(kGlossyRoomXml));
    auto one = make({{"neepp", "auto"}});
    one->prepare(*room);
    const auto &p1 = dynamic_cast<AutoIntegrator &>(*one).pilot();
    ASSERT_EQ(p1.size(), 1u);
    EXPECT_EQ(p1[0].seconds_per_sample, 0) << "a pilot ran where nothing could be chosen";
    EXPECT_EQ(dynamic_cast<AutoIntegrator &>(*one).picked(), "nee");
}

// Whatever the pilot picks renders plain NEE's image: each candidate forced through the saved state (the
// first word names it), rendered through the auto integrator, against plain NEE.
TEST(NeeppAuto, EveryCandidateItMayPickAgreesWithPlainNee) {
    const std::string path = write_temp_scene(kCourtXml);
    auto scene = load_scene(path);
    const BlockMoments nee = block_moments(path, "path", Options(OptionMap{{"max_depth", "4"}}), 4, 32, 500);
    for (const AutoCandidate &c : auto_candidates(true)) {  // guiding's candidate too
        std::vector<std::vector<double>> per_seed;
        for (int s = 0; s < 4; ++s) {
            OptionMap o = c.overrides;
            o["max_depth"] = "4";
            auto fresh = make(o);  // the candidate's own state, as a first render would save it
            fresh->prepare(*scene);
            const std::string state = c.name + '\n' + fresh->save_state();
            auto integrator = make({{"neepp", "auto"}, {"max_depth", "4"}, {"auto_guiding", "true"}});
            RenderJob job;
            job.spp = 32;
            job.seed = 900 + 31 * s;
            job.integrator_state = &state;
            RenderResult r = render(*scene, *integrator, job);
            EXPECT_EQ(dynamic_cast<AutoIntegrator &>(*integrator).picked(), c.name);
            per_seed.push_back(block_means(r.image, 6, 6));
        }
        expect_same_image(nee, moments_over_seeds(per_seed), "neepp=auto forced to " + c.name);
    }
}

// -I auto_guiding=true: path guiding is a candidate on every scene, one light included (a pilot then runs
// where none did), and learns from its warm-up passes before it is measured; the pick follows the rule.
TEST(NeeppAuto, GuidingIsACandidateWhereAsked) {
    auto room = load_scene(write_temp_scene(kGlossyRoomXml));
    auto integrator = make({{"neepp", "auto"}, {"auto_guiding", "true"}});
    auto &auto_integrator = dynamic_cast<AutoIntegrator &>(*integrator);
    auto_integrator.prepare(*room);
    const auto &pilot = auto_integrator.pilot();
    ASSERT_EQ(pilot.size(), 2u) << "one light: plain NEE and guiding";
    EXPECT_EQ(pilot[0].name, "nee");
    EXPECT_EQ(pilot[1].name, "guided");
    for (const AutoPilotResult &r : pilot) {
        EXPECT_GT(r.relative_variance, 0) << r.name;
        EXPECT_GT(r.seconds_per_sample, 0) << r.name;
    }
    EXPECT_EQ(auto_integrator.picked(), pilot[1].efficiency > AutoIntegrator::kMargin ? "guided" : "nee");
    // Forced to guiding (as a resumed render is), the guide it renders with learned from the warm-up.
    auto forced = make({{"neepp", "auto"}, {"auto_guiding", "true"}});
    auto fresh = make({{"guiding", "sdtree"}});
    fresh->prepare(*room);
    RenderJob job;
    job.spp = 8;
    job.seed = 5;
    render(*room, *fresh, job);
    const std::string state = "guided\n" + fresh->save_state();
    job.integrator_state = &state;
    render(*room, *forced, job);
    EXPECT_EQ(dynamic_cast<AutoIntegrator &>(*forced).picked(), "guided");
    EXPECT_EQ(forced->describe()["guiding"], "sdtree");
    EXPECT_TRUE(forced->statistics().contains("guiding"));
    // Without the option: no guiding candidate, and no pilot with one light.
    auto plain = make({{"neepp", "auto"}});
    plain->prepare(*room);
    EXPECT_EQ(dynamic_cast<AutoIntegrator &>(*plain).pilot().size(), 1u);
    EXPECT_THROW(make({{"neepp", "auto"}, {"guiding", "sdtree"}}), std::invalid_argument);
    EXPECT_THROW(make_integrator("volpath", Options(OptionMap{{"neepp", "auto"}, {"auto_guiding", "true"}})),
                 std::invalid_argument);
    EXPECT_THROW(make({{"auto_guiding", "true"}}), std::invalid_argument) << "only with neepp=auto";
}

TEST(NeeppAuto, RefusesAStateThatNamesNoCandidate) {
    auto scene = load_scene(write_temp_scene(kGlossyRoomXml));
    auto integrator = make({{"neepp", "auto"}});
    integrator->prepare(*scene);
    EXPECT_THROW(integrator->restore_state(*scene, "no-such-candidate\n"), std::invalid_argument);
    EXPECT_THROW(integrator->restore_state(*scene, "no newline"), std::invalid_argument);
}

}  // namespace
