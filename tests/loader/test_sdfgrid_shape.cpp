// The `sdfgrid` shape through the loader: the .vol file, `normals` and to_world reach the shape (also
// through a shapegroup's instance, whose to_world applies after the shape's), and each thing Mitsuba
// refuses or neepp cannot read is an error naming the scene's line, and the grid file where it is at fault.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include "common/volume_grid_writer.h"
#include "neepp/io/scene_error.h"
#include "neepp/shapes/sdf_grid_shape.h"
#include "test_scenes.h"

using namespace neepp;
using neepp::testing::VolumeGridFile;

namespace {

// A scene whose line 9 holds `body` (an sdfgrid, a shapegroup...), beside grid.vol holding `grid`.
std::string scene_with(const std::string &body, const VolumeGridFile &grid) {
    const std::string path = neepp::testing::write_temp_scene(
        neepp::testing::scene_header_xml(2, 45, "0,0,5", "0,0,0", 8, 8) + "  <emitter type=\"constant\"/>\n" + body +
            "\n</scene>\n",
        "sdf_scene.xml");
    std::ofstream(std::filesystem::path(path).parent_path() / "grid.vol", std::ios::binary)
        << neepp::testing::volume_grid_bytes(grid);
    return path;
}

const char *kGridFile = R"(<string name="filename" value="grid.vol"/>)";

std::string error_of(const std::string &body, const VolumeGridFile &grid = neepp::testing::sphere_sdf_grid(9)) {
    try {
        load_scene(scene_with(body, grid));
    } catch (const SceneError &e) {
        return e.what();
    }
    ADD_FAILURE() << "loaded: " << body;
    return "";
}

}  // namespace

TEST(SdfGridShape, TheGridNormalsAndToWorldReachTheShape) {
    auto scene = load_scene(scene_with(std::string(R"(<shape type="sdfgrid">)") + kGridFile +
                                           R"(<string name="normals" value="analytic"/>
           <transform name="to_world"><scale value="2"/><translate x="-1" y="-1" z="-1"/></transform></shape>)",
                                       neepp::testing::sphere_sdf_grid(21)));
    ASSERT_EQ(scene->shapes().size(), 1u);
    const auto &s = dynamic_cast<const SdfGridShape &>(*scene->shapes()[0]);
    EXPECT_EQ(s.grid->size(0), 21u);
    EXPECT_EQ(s.grid->normals(), SdfGrid::Normals::Analytic);
    // [0, 1]^3 scaled by 2 and moved to [-1, 1]^3, the sphere of radius 0.3 with it: 0.6 about the origin.
    EXPECT_EQ(s.bounds().lo, Vec3(-1.f));
    EXPECT_EQ(s.bounds().hi, Vec3(1.f));
    SurfaceInteraction si;
    ASSERT_TRUE(scene->intersect(Ray{{0, 0, 5}, {0, 0, -1}}, si));
    EXPECT_NEAR(si.t, 4.4f, 1e-3f);
    EXPECT_NEAR(si.n.z, 1.f, 1e-2f);
    EXPECT_EQ(si.uv.x, 0.f);  // Mitsuba's sdfgrid has no uv
    EXPECT_EQ(si.uv.y, 0.f);
    // Smooth normals are the default.
    auto plain = load_scene(scene_with(std::string(R"(<shape type="sdfgrid">)") + kGridFile + "</shape>",
                                       neepp::testing::sphere_sdf_grid(21)));
    EXPECT_EQ(dynamic_cast<const SdfGridShape &>(*plain->shapes()[0]).grid->normals(), SdfGrid::Normals::Smooth);
}

TEST(SdfGridShape, AnInstanceMovesTheGridAfterItsOwnToWorld) {
    // The group's grid is moved by +1 in x, then the instance scales by 2: the sphere's centre lands at
    // (2 (0.5 + 1), 1, 1) = (3, 1, 1), radius 0.6; two instances share one grid.
    auto scene = load_scene(scene_with(std::string(R"(<shape type="shapegroup" id="g"><shape type="sdfgrid">)") + kGridFile +
                                           R"(<transform name="to_world"><translate x="1"/></transform></shape></shape>
           <shape type="instance"><ref id="g"/><transform name="to_world"><scale value="2"/></transform></shape>
           <shape type="instance"><ref id="g"/><transform name="to_world"><rotate y="1" angle="90"/></transform></shape>)",
                                       neepp::testing::sphere_sdf_grid(21)));
    ASSERT_EQ(scene->shapes().size(), 2u);
    EXPECT_EQ(dynamic_cast<const SdfGridShape &>(*scene->shapes()[0]).grid,
              dynamic_cast<const SdfGridShape &>(*scene->shapes()[1]).grid);
    SurfaceInteraction si;
    ASSERT_TRUE(scene->intersect(Ray{{3, 1, 5}, {0, 0, -1}}, si));
    EXPECT_EQ(si.shape, scene->shapes()[0].get());
    EXPECT_NEAR(si.t, 5 - 1 - 0.6f, 2e-3f);
    // The second, rotated by 90 degrees about y: its centre (1.5, 0.5, 0.5) goes to (0.5, 0.5, -1.5).
    ASSERT_TRUE(scene->intersect(Ray{{0.5f, 0.5f, -5}, {0, 0, 1}}, si));
    EXPECT_EQ(si.shape, scene->shapes()[1].get());
    EXPECT_NEAR(si.t, 5 - 1.5f - 0.3f, 2e-3f);
}

TEST(SdfGridShape, WhatMitsubaRefusesIsAnErrorNamingTheLine) {
    const std::string open = R"(<shape type="sdfgrid">)";
    std::string msg = error_of(open + kGridFile + R"(<string name="normals" value="flat"/></shape>)");
    EXPECT_NE(msg.find("sdf_scene.xml:9:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"flat\""), std::string::npos) << msg;
    msg = error_of(open + "</shape>");
    EXPECT_NE(msg.find("needs a 'filename'"), std::string::npos) << msg;
    msg = error_of(open + kGridFile + R"(<emitter type="area"/></shape>)");
    EXPECT_NE(msg.find("cannot carry an area emitter"), std::string::npos) << msg;
}

TEST(SdfGridShape, ABadGridFileNamesTheSceneLineAndTheFile) {
    VolumeGridFile two_channels = neepp::testing::sphere_sdf_grid(3);
    two_channels.channels = 2;
    two_channels.size[2] = 1;  // the same 18 values, as 3 x 3 x 1 points of 2 channels
    VolumeGridFile flat = neepp::testing::sphere_sdf_grid(3);
    flat.size[2] = 1, flat.values.resize(9);
    VolumeGridFile empty = neepp::testing::sphere_sdf_grid(4, 0.5f, 0.5f, 0.5f, 0.01f);  // no grid point within
    VolumeGridFile nan = neepp::testing::sphere_sdf_grid(4);
    nan.values[7] = std::nanf("");
    for (const auto &[grid, needle] : std::vector<std::pair<VolumeGridFile, std::string>>{
             {two_channels, "has 2 channels, expected 1"},
             {flat, "at least 2 points along each axis"},
             {empty, "no surface"},
             {nan, "(3, 1, 0) is not finite"}}) {
        const std::string msg = error_of(std::string(R"(<shape type="sdfgrid">)") + kGridFile + "</shape>", grid);
        EXPECT_NE(msg.find("sdf_scene.xml:9:"), std::string::npos) << msg;
        EXPECT_NE(msg.find("grid.vol: "), std::string::npos) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
    const std::string msg = error_of(R"(<shape type="sdfgrid"><string name="filename" value="missing.vol"/></shape>)");
    EXPECT_NE(msg.find("missing.vol: cannot open"), std::string::npos) << msg;
}

TEST(SdfGridShape, MeshOptionsItLacksAreReportedUnused) {
    const auto problems = check_scene(scene_with(std::string(R"(<shape type="sdfgrid">)") + kGridFile +
                                                     R"(<boolean name="face_normals" value="true"/></shape>)",
                                                 neepp::testing::sphere_sdf_grid(9)));
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_FALSE(problems[0].error);
    EXPECT_NE(problems[0].problem.find("face_normals"), std::string::npos) << problems[0].problem;
}

// A header that gives fewer values than the file holds (here a 4^3 grid written under a 4 x 4 x 2 header):
// the shape is built from the values it gives, as Mitsuba builds it, with a warning at the shape's line.
TEST(SdfGridShape, DataBeyondTheHeaderIsWarnedAbout) {
    VolumeGridFile half = neepp::testing::sphere_sdf_grid(4);
    half.size[2] = 2;
    const auto problems = check_scene(scene_with(std::string(R"(<shape type="sdfgrid">)") + kGridFile + "</shape>", half));
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_FALSE(problems[0].error);
    EXPECT_EQ(problems[0].line, 9);
    EXPECT_NE(problems[0].problem.find("grid.vol: 128 bytes after the 4 x 4 x 2 points of 1 channel"), std::string::npos)
        << problems[0].problem;
    EXPECT_NE(problems[0].problem.find("exactly 2 times as many values"), std::string::npos) << problems[0].problem;
}
