// Mitsuba 3's `linearcurve` and `bsplinecurve` shapes as the loader builds them: to_world moves the
// control points but leaves their radii (Mitsuba's), an instance moves and scales the whole tube, curves
// cannot emit (Mitsuba cannot render that either), and a broken curve file is named with its line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include "neepp/shapes/curve_shape.h"
#include "neepp/loader/supported_plugins.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// A scene of one curve file (written beside the scene) and the shapes given; returns the scene's path.
std::string curve_scene_file(const std::string &shapes, const std::string &curves = "-1 0 0 0.25\n1 0 0 0.25\n") {
    const std::string path = write_temp_scene(scene_header_xml(2, 40, "0,0,5", "0,0,0", 8, 8) + shapes +
                                              "\n<emitter type=\"constant\"/>\n</scene>\n",
                                              "curves.xml");
    std::ofstream(std::filesystem::path(path).parent_path() / "line.txt") << curves;
    return path;
}

// The distance at which a ray straight down from (x, 0, 5) first hits the scene, or -1.
float depth_at(const Scene &scene, float x) {
    SurfaceInteraction si;
    return scene.intersect(Ray{Vec3(x, 0, 5), Vec3(0, 0, -1)}, si) ? si.t : -1.f;
}

std::string load_error(const std::string &path) {
    try {
        load_scene(path);
    } catch (const std::exception &e) {
        return e.what();
    }
    ADD_FAILURE() << "loaded, but should not have";
    return "";
}

TEST(CurveShapes, ToWorldMovesControlPointsButNotRadii) {
    for (const char *type : {"linearcurve", "bsplinecurve"}) {
        // Four points on the x axis (a B-spline through collinear points is the straight line), stretched
        // 2x along x and moved up 1 by to_world: radius 0.25 still, not 0.5.
        auto scene = load_scene(curve_scene_file(std::string("<shape type=\"") + type + R"("><string name="filename" value="line.txt"/>
            <transform name="to_world"><scale x="2" y="2" z="2"/><translate z="1"/></transform></shape>)",
                                                 "-1.5 0 0 0.25\n-0.5 0 0 0.25\n0.5 0 0 0.25\n1.5 0 0 0.25\n"));
        EXPECT_NEAR(depth_at(*scene, 0.3f), 5 - 1.25f, 1e-4f) << type;
        EXPECT_NEAR(depth_at(*scene, 0.8f), 5 - 1.25f, 1e-4f) << type;  // the B-spline ends at x = 0.5 unstretched
        EXPECT_NE(dynamic_cast<const CurveShape *>(scene->shapes()[0].get()), nullptr);
        EXPECT_EQ(scene->triangle_count(), 0u);
    }
}

TEST(CurveShapes, AnInstanceScalesTheTubeWithIt) {
    const std::string group = R"(<shape type="shapegroup" id="g"><shape type="linearcurve"><string name="filename" value="line.txt"/></shape></shape>)";
    auto scene = load_scene(curve_scene_file(group + R"(<shape type="instance"><ref id="g"/>
        <transform name="to_world"><scale value="2"/><translate z="1"/></transform></shape>)"));
    EXPECT_NEAR(depth_at(*scene, 1.5f), 5 - 1.5f, 1e-4f);  // radius 0.5 about z = 1, out to x = 2
    const std::string msg = load_error(curve_scene_file(group + R"(<shape type="instance"><ref id="g"/>
        <transform name="to_world"><scale x="2" y="1" z="1"/></transform></shape>)"));
    EXPECT_NE(msg.find("curves.xml:8:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("scale uniformly"), std::string::npos) << msg;
}

TEST(CurveShapes, CurvesCannotEmit) {
    const std::string msg = load_error(curve_scene_file(R"(<shape type="bsplinecurve"><string name="filename" value="line.txt"/>
        <emitter type="area"/></shape>)", "0 0 0 1\n1 0 0 1\n2 0 0 1\n3 0 0 1\n"));
    EXPECT_NE(msg.find("curves.xml:9:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("a bsplinecurve cannot carry an emitter"), std::string::npos) << msg;
}

TEST(CurveShapes, BrokenCurveFilesNameTheSceneLineAndTheFileLine) {
    std::string msg = load_error(curve_scene_file(R"(<shape type="bsplinecurve"><string name="filename" value="line.txt"/></shape>)"));
    EXPECT_NE(msg.find("curves.xml:8:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("line.txt:1: a B-spline curve needs at least 4 control points"), std::string::npos) << msg;
    msg = load_error(curve_scene_file(R"(<shape type="linearcurve"><string name="filename" value="line.txt"/></shape>)",
                                      "0 0 0 1\n1 0 0 1\n\n2 zero 0 1\n"));
    EXPECT_NE(msg.find("line.txt:4: expected four numbers"), std::string::npos) << msg;
    msg = load_error(curve_scene_file(R"(<shape type="linearcurve"><string name="filename" value="elsewhere.txt"/></shape>)"));
    EXPECT_NE(msg.find("elsewhere.txt"), std::string::npos) << msg;
}

TEST(CurveShapes, NormalsOptionsAreNotCurveProperties) {
    // Mitsuba's curves read neither flip_normals nor face_normals; neepp warns of properties nothing reads.
    const std::vector<SceneProblem> problems = check_scene(curve_scene_file(
        R"(<shape type="linearcurve"><string name="filename" value="line.txt"/><boolean name="flip_normals" value="true"/></shape>)"));
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_FALSE(problems[0].error);
    EXPECT_NE(problems[0].problem.find("flip_normals"), std::string::npos) << problems[0].problem;
}

TEST(CurveShapes, ListedAsSupported) {
    const auto &shapes = supported_names("shape");
    EXPECT_NE(std::find(shapes.begin(), shapes.end(), "linearcurve"), shapes.end());
    EXPECT_NE(std::find(shapes.begin(), shapes.end(), "bsplinecurve"), shapes.end());
}

}  // namespace
