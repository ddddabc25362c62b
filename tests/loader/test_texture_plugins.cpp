// Texture plugins through the loader: what each element builds, and the errors of bad ones.
#include <gtest/gtest.h>
#include "neepp/io/scene_error.h"
#include "neepp/loader/factories.h"
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
