// The `serialized` shape through the loader: shape_index, to_world and face_normals reach the mesh, and a
// bad file's error names both the scene's line and the mesh file.
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include "common/serialized_writer.h"
#include "neepp/shapes/triangle_mesh.h"
#include "neepp/io/scene_error.h"
#include "test_scenes.h"

using namespace neepp;
using neepp::testing::SerializedTestMesh;

namespace {

std::string scene_with_serialized(const std::string &shape_body, const std::string &file_bytes) {
    const std::string path = neepp::testing::write_temp_scene(neepp::testing::scene_header_xml(2, 45, "0,0,5", "0,0,0", 8, 8) +
                                                  "  <emitter type=\"constant\"/>\n  <shape type=\"serialized\">" + shape_body +
                                                  "</shape>\n</scene>\n",
                                              "serialized_scene.xml");
    std::ofstream(std::filesystem::path(path).parent_path() / "meshes.serialized", std::ios::binary) << file_bytes;
    return path;
}

SerializedTestMesh triangle(float z, bool normals) {
    SerializedTestMesh m;
    m.positions = {0, 0, z, 1, 0, z, 0, 1, z};
    if (normals) m.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    m.indices = {0, 1, 2};
    return m;
}

}  // namespace

TEST(SerializedShape, ShapeIndexToWorldAndNormalsReachTheMesh) {
    const std::string file = neepp::testing::serialized({triangle(0, false), triangle(1, true)});
    auto scene = load_scene(scene_with_serialized(
        R"(<string name="filename" value="meshes.serialized"/><integer name="shape_index" value="1"/>
           <transform name="to_world"><scale value="2"/><translate x="1"/></transform>)", file));
    ASSERT_EQ(scene->shapes().size(), 1u);
    const auto &s = dynamic_cast<const TriangleMesh &>(*scene->shapes()[0]);
    ASSERT_EQ(s.positions.size(), 3u);
    EXPECT_EQ(s.positions[1], Vec3(3, 0, 2));  // (1, 0, 1) scaled by 2, moved by 1 in x
    ASSERT_EQ(s.normals.size(), 3u);
    EXPECT_EQ(s.normals[0], Vec3(0, 0, 1));
    // The first mesh has none: they are computed, unless face_normals asks for none.
    auto first = load_scene(scene_with_serialized(R"(<string name="filename" value="meshes.serialized"/>)", file));
    EXPECT_EQ(dynamic_cast<const TriangleMesh &>(*first->shapes()[0]).normals.size(), 3u);
    auto faceted = load_scene(scene_with_serialized(
        R"(<string name="filename" value="meshes.serialized"/><boolean name="face_normals" value="true"/>)", file));
    const auto &faceted_mesh = dynamic_cast<const TriangleMesh &>(*faceted->shapes()[0]);
    EXPECT_TRUE(faceted_mesh.face_normals);
    EXPECT_TRUE(faceted_mesh.normals.empty());
}

TEST(SerializedShape, ABadFileNamesTheSceneLineAndTheFile) {
    const std::string file = neepp::testing::serialized({triangle(0, false)});
    for (const auto &[body, needle] : std::vector<std::pair<std::string, std::string>>{
             {R"(<string name="filename" value="meshes.serialized"/><integer name="shape_index" value="2"/>)",
              "shape_index 2 is out of range: the file holds 1 mesh"},
             {R"(<string name="filename" value="missing.serialized"/>)", "missing.serialized: cannot open"}}) {
        try {
            load_scene(scene_with_serialized(body, file));
            ADD_FAILURE() << "loaded: " << body;
        } catch (const SceneError &e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find("serialized_scene.xml:9:"), std::string::npos) << msg;
            EXPECT_NE(msg.find(needle), std::string::npos) << msg;
        }
    }
}
