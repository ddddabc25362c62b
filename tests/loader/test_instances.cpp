// Mitsuba's shapegroup and instance: an instance puts the group's shapes, with their own materials,
// where the same shapes placed by hand would be, and renders as they do; a group alone renders nothing;
// what Mitsuba refuses (nested groups and instances, emitters in a group, an instance without its
// group) is refused with the line.
#include <gtest/gtest.h>
#include "neepp/shapes/triangle_mesh.h"
#include "neepp/shapes/sphere.h"
#include "neepp/io/scene_error.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

const std::string kHeader = scene_header_xml(4, 45, "0,2,5", "0,0.5,0", 32, 24) +
                            R"(  <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="4"/></transform>
    <emitter type="area"><rgb name="radiance" value="0.2"/></emitter></shape>
  <shape type="sphere"><point name="center" x="0" y="4" z="0"/><float name="radius" value="0.5"/>
    <emitter type="area"><rgb name="radiance" value="20"/></emitter></shape>
)";

// The group's two shapes in their own frames, and the two placements of the instances.
const char *kCubeFrame = R"(<scale value="0.4"/><rotate y="1" angle="30"/><translate x="0.5" y="0.4"/>)";
const char *kSphereFrame = R"(<translate x="-0.5" y="0.3"/>)";
const char *kPlacements[2] = {R"(<rotate y="1" angle="-20"/><translate x="-1" z="0.5"/>)",
                              R"(<scale value="0.7"/><rotate x="1" angle="10"/><translate x="1.2" y="0.1" z="-0.5"/>)"};

std::string cube(const std::string &frame) {
    return R"(<shape type="cube"><transform name="to_world">)" + frame +
           R"(</transform><bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></shape>)";
}
std::string sphere(const std::string &frame) {
    return R"(<shape type="sphere"><float name="radius" value="0.3"/><transform name="to_world">)" + frame +
           R"(</transform><bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.3,0.2"/></bsdf></shape>)";
}

std::string instanced_scene() {
    std::string xml = kHeader + "<shape type=\"shapegroup\" id=\"pair\">" + cube(kCubeFrame) + sphere(kSphereFrame) + "</shape>\n";
    for (const char *placement : kPlacements)
        xml += std::string("<shape type=\"instance\"><ref id=\"pair\"/><transform name=\"to_world\">") + placement +
               "</transform></shape>\n";
    return xml + "</scene>\n";
}

// The same shapes placed by hand: a transform's steps apply in order, so the group's frame and then the
// instance's placement is the instance's world transform.
std::string by_hand_scene() {
    std::string xml = kHeader;
    for (const char *placement : kPlacements)
        xml += cube(std::string(kCubeFrame) + placement) + sphere(std::string(kSphereFrame) + placement) + "\n";
    return xml + "</scene>\n";
}

std::string scene_with(const std::string &body) { return kHeader + body + "\n</scene>\n"; }

std::string load_error(const std::string &xml) {
    try {
        load_scene(write_temp_scene(xml, "instances.xml"));
    } catch (const SceneError &e) {
        return e.what();
    }
    ADD_FAILURE() << "scene loaded but should not have:\n" << xml;
    return "";
}

double mean(const Image &img) {
    double sum = 0;
    for (float v : img.data) sum += v;
    return sum / double(img.data.size());
}

}  // namespace

TEST(Instances, PutTheGroupsShapesWhereHandPlacedOnesWouldBe) {
    auto instanced = load_scene(write_temp_scene(instanced_scene(), "instanced.xml"));
    auto by_hand = load_scene(write_temp_scene(by_hand_scene(), "by_hand.xml"));
    ASSERT_EQ(instanced->shapes().size(), 2u + 4u);  // the floor and light, then two shapes per instance
    ASSERT_EQ(by_hand->shapes().size(), instanced->shapes().size());
    for (size_t i = 2; i < instanced->shapes().size(); ++i) {
        EXPECT_EQ(instanced->shapes()[i]->area_light, nullptr);
        const auto *sa = dynamic_cast<const Sphere *>(instanced->shapes()[i].get());
        if (sa) {
            const Sphere &a = *sa, &b = dynamic_cast<const Sphere &>(*by_hand->shapes()[i]);
            EXPECT_LT(norm(a.center - b.center), 1e-5f) << i;
            EXPECT_NEAR(a.radius, b.radius, 1e-5f) << i;
            for (int k = 0; k < 3; ++k) EXPECT_LT(norm(a.axes[k] - b.axes[k]), 1e-5f) << i << " " << k;
            continue;
        }
        const auto &a = dynamic_cast<const TriangleMesh &>(*instanced->shapes()[i]);
        const auto &b = dynamic_cast<const TriangleMesh &>(*by_hand->shapes()[i]);
        ASSERT_EQ(a.positions.size(), b.positions.size());
        EXPECT_EQ(a.indices, b.indices);
        for (size_t k = 0; k < a.positions.size(); ++k) {
            EXPECT_LT(norm(a.positions[k] - b.positions[k]), 1e-5f) << i << " " << k;
            EXPECT_LT(norm(a.normals[k] - b.normals[k]), 1e-5f) << i << " " << k;
        }
    }
    // Each member keeps its own material, one object shared by its copies.
    EXPECT_EQ(instanced->shapes()[2]->bsdf, instanced->shapes()[4]->bsdf);
    EXPECT_EQ(instanced->shapes()[3]->bsdf, instanced->shapes()[5]->bsdf);
    EXPECT_NE(instanced->shapes()[2]->bsdf, instanced->shapes()[3]->bsdf);

    const Image a = render_scene_file(write_temp_scene(instanced_scene(), "instanced.xml"), 8, 1, Options{}).image;
    const Image b = render_scene_file(write_temp_scene(by_hand_scene(), "by_hand.xml"), 8, 1, Options{}).image;
    ASSERT_EQ(a.data.size(), b.data.size());
    // The same sample sequences over geometry equal to rounding: the images agree but for the odd path
    // that a last-bit difference sends elsewhere.
    size_t differing = 0;
    for (size_t k = 0; k < a.data.size(); ++k) differing += std::abs(a.data[k] - b.data[k]) > 1e-4f * (1 + b.data[k]);
    EXPECT_LT(differing, a.data.size() / 100);
    EXPECT_NEAR(mean(a), mean(b), 1e-3 * mean(b));
    EXPECT_GT(mean(a), 0.01);
}

TEST(Instances, AGroupAloneAddsNothing) {
    auto scene = load_scene(write_temp_scene(scene_with("<shape type=\"shapegroup\" id=\"g\">" + cube(kCubeFrame) + "</shape>"),
                                             "group_alone.xml"));
    EXPECT_EQ(scene->shapes().size(), 2u);
}

TEST(Instances, WhatMitsubaRefusesIsRefusedWithTheLine) {
    const std::string group = "<shape type=\"shapegroup\" id=\"g\">" + cube(kCubeFrame) + "</shape>\n";
    auto expect_error = [&](const std::string &body, const std::string &line, const std::string &needle) {
        const std::string msg = load_error(scene_with(body));
        EXPECT_NE(msg.find("instances.xml:" + line + ":"), std::string::npos) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    };
    // The header ends on line 12; the body starts on line 13.
    expect_error("<shape type=\"shapegroup\">\n" + group + "</shape>", "14", "a shapegroup cannot hold another shapegroup");
    expect_error(group + "<shape type=\"shapegroup\">\n<shape type=\"instance\"><ref id=\"g\"/></shape></shape>", "15",
                 "a shapegroup cannot hold an instance");
    expect_error("<shape type=\"shapegroup\">\n<shape type=\"sphere\">\n<emitter type=\"area\"/></shape></shape>", "15",
                 "a shape in a shapegroup cannot carry an emitter");
    expect_error("<shape type=\"shapegroup\">\n<bsdf type=\"diffuse\"/></shape>", "14", "a shapegroup holds only shapes, not <bsdf>");
    expect_error("\n<shape type=\"instance\"/>", "14", "an instance needs a <ref> to a shapegroup");
    expect_error("<bsdf type=\"diffuse\" id=\"d\"/>\n<shape type=\"instance\"><ref id=\"d\"/></shape>", "14",
                 "an instance holds only a <ref> to a shapegroup, not <bsdf type=\"diffuse\">");
    expect_error(group + "<shape type=\"shapegroup\" id=\"h\">" + cube(kCubeFrame) +
                     "</shape>\n<shape type=\"instance\"><ref id=\"g\"/><ref id=\"h\"/></shape>", "15",
                 "an instance references a single shapegroup");
    expect_error("\n<shape type=\"instance\"><ref id=\"nothing\"/></shape>", "14", "unknown id \"nothing\"");
    // A sphere stays a sphere: an instance may not stretch it.
    expect_error("<shape type=\"shapegroup\" id=\"s\">" + sphere("") + "</shape>\n<shape type=\"instance\"><ref id=\"s\"/>"
                 "<transform name=\"to_world\"><scale x=\"2\"/></transform></shape>", "14", "sphere to_world must scale uniformly");
}

TEST(Instances, ACheckListsAGroupsProblemsOnce) {
    const std::string xml = scene_with("<shape type=\"shapegroup\" id=\"g\">\n<shape type=\"teapot\"/></shape>\n"
                                       "<shape type=\"instance\"><ref id=\"g\"/></shape>\n"
                                       "<shape type=\"instance\"><ref id=\"g\"/></shape>");
    const std::vector<SceneProblem> problems = check_scene(write_temp_scene(xml, "check_group.xml"));
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(problems[0].line, 14);
    EXPECT_NE(problems[0].problem.find("teapot"), std::string::npos);
}
