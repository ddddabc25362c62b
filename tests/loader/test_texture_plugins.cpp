// Texture plugins through the loader: what each element builds, and the errors of bad ones.
#include <gtest/gtest.h>
#include "neepp/io/scene_error.h"
#include "neepp/loader/factories.h"
#include "neepp/textures/mesh_attribute_texture.h"
#include <filesystem>
#include <fstream>
#include "test_scenes.h"

using namespace neepp;

namespace {

// The textures declared at the top level of a scene made of `body`, in document order.
std::vector<TexturePtr> load_textures(const std::string &body) {
    auto root = parse_mitsuba_xml(neepp::testing::write_temp_scene("<scene version=\"3.0.0\">" + body + "</scene>"));
    loader::Factories f;
    std::vector<TexturePtr> out;
    for (const auto &t : root->children_with_tag("texture")) out.push_back(f.texture(*t));
    return out;
}

}  // namespace

// rawconstant keeps its value as written: no clamping to [0, 1], no colour conversion, negatives kept,
// and a float is broadcast to the three channels.
TEST(RawConstantTexture, ValueIsUsedRaw) {
    auto t = load_textures(R"(<texture type="rawconstant"><vector name="value" value="0.5, -2, 3.25"/></texture>
        <texture type="rawconstant"><float name="value" value="1.5"/></texture>)");
    ASSERT_EQ(t.size(), 2u);
    SurfaceInteraction si;
    EXPECT_EQ(t[0]->eval(si), Color(0.5f, -2.f, 3.25f));
    EXPECT_TRUE(t[0]->is_constant());
    EXPECT_EQ(t[1]->eval(si), Color(1.5f));
    EXPECT_FLOAT_EQ(t[1]->eval_1(si), 1.5f);
    EXPECT_EQ(t[1]->mean(), Color(1.5f));
}

TEST(RawConstantTexture, MissingValueIsAnError) {
    try {
        load_textures("\n<texture type=\"rawconstant\"/>");
        FAIL() << "expected an error";
    } catch (const SceneError &e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find(":2:"), std::string::npos) << msg;
        EXPECT_NE(msg.find("'value'"), std::string::npos) << msg;
    }
}

namespace {

// A scene with a PLY quad (two triangles: 0 1 2 and 0 2 3) carrying a vertex colour and a per-face
// weight, its reflectance given by `texture`, plus `extra` (more shapes).
std::string attribute_scene(const std::string &texture, const std::string &extra = "") {
    const std::string path = neepp::testing::write_temp_scene(
        neepp::testing::scene_header_xml(2, 45, "0,0,5", "0,0,0", 8, 8) + "<emitter type=\"constant\"/>\n" +
        "<shape type=\"ply\"><string name=\"filename\" value=\"quad.ply\"/><bsdf type=\"diffuse\">" + texture +
        "</bsdf></shape>\n" + extra + "</scene>\n");
    std::ofstream(std::filesystem::path(path).parent_path() / "quad.ply") << R"(ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
property float r
property float g
property float b
element face 2
property list uchar int vertex_indices
property float weight_0
end_header
0 0 0 1 0 0
2 0 0 0 1 0
2 2 0 0 0 1
0 2 0 1 1 1
3 0 1 2 0.25
3 0 2 3 0.75
)";
    return path;
}

std::string load_error(const std::string &path) {
    try {
        load_scene(path);
    } catch (const SceneError &e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a SceneError";
    return "";
}

}  // namespace

// mesh_attribute: a vertex attribute is interpolated barycentrically over the triangle hit, a face
// attribute is the triangle's, both times scale; an attribute the shape lacks fails at load, naming it.
TEST(MeshAttributeTexture, InterpolatesVertexAndReadsFaceAttributes) {
    auto scene = load_scene(attribute_scene(
        R"(<texture name="reflectance" type="mesh_attribute"><string name="name" value="vertex_color"/></texture>)"));
    const Shape &shape = *scene->shapes().at(0);
    SurfaceInteraction si;
    si.shape = &shape;
    si.prim_index = 0;
    si.p = Vec3(1.5f, 0.5f, 0.f);  // barycentrics (0.25, 0.5, 0.25) on triangle 0 1 2
    const Color c = MeshAttributeTexture("vertex_color").eval(si);
    EXPECT_NEAR(c.x, 0.25f, 1e-5f);
    EXPECT_NEAR(c.y, 0.5f, 1e-5f);
    EXPECT_NEAR(c.z, 0.25f, 1e-5f);
    si.prim_index = 1;
    si.p = Vec3(0.5f, 1.5f, 0.f);
    EXPECT_NEAR(MeshAttributeTexture("face_weight", 2.f).eval(si).y, 1.5f, 1e-6f);
    EXPECT_THROW(MeshAttributeTexture("color"), std::invalid_argument);
}

TEST(MeshAttributeTexture, MissingAttributeOrBadNameFailsAtLoad) {
    std::string msg = load_error(attribute_scene(
        R"(<texture name="reflectance" type="mesh_attribute"><string name="name" value="vertex_normal"/></texture>)"));
    EXPECT_NE(msg.find("\"vertex_normal\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("vertex_color, face_weight"), std::string::npos) << msg;
    msg = load_error(attribute_scene(R"(<ref name="reflectance" id="w"/>)",
                                     R"(<texture type="mesh_attribute" id="w"><string name="name" value="face_weight"/></texture>
<shape type="sphere"><bsdf type="diffuse"><ref name="reflectance" id="w"/></bsdf></shape>)"));
    EXPECT_NE(msg.find("<shape type=\"sphere\">"), std::string::npos) << msg;
    EXPECT_NE(msg.find("none"), std::string::npos) << msg;
    msg = load_error(attribute_scene(
        R"(<texture name="reflectance" type="mesh_attribute"><string name="name" value="color"/></texture>)"));
    EXPECT_NE(msg.find("\"vertex_\" or \"face_\""), std::string::npos) << msg;
}
