// Mitsuba 3 XML parsing: the real scenes, parameters, references, transforms, and error messages.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include "neepp/io/xml_tree.h"
#include "common/temp_dir.h"

using namespace neepp;
using neepp::testing::TempDir;
namespace fs = std::filesystem;

namespace {


const char *kSceneDirs[] = {"bathroom", "classroom", "cornell-box", "living-room", "staircase", "veach-ajar"};

fs::path scenes_dir() { return fs::path(NEEPP_SHARED_DIR) / "scenes"; }

// Expects a SceneError whose message starts with "file:line:" and contains `needle`.
void expect_error(const std::function<void()> &f, const std::string &file, int line, const std::string &needle) {
    try {
        f();
        ADD_FAILURE() << "expected a SceneError containing \"" << needle << "\"";
    } catch (const SceneError &e) {
        std::string msg = e.what();
        std::string prefix = file + ":" + std::to_string(line) + ":";
        EXPECT_EQ(msg.rfind(prefix, 0), 0u) << msg << "\n  should start with " << prefix;
        EXPECT_NE(msg.find(needle), std::string::npos) << msg << "\n  should mention " << needle;
        EXPECT_EQ(e.line, line);
    }
}

std::string scene(const std::string &body) { return "<scene version=\"3.0.0\">\n" + body + "</scene>\n"; }

void expect_near(const Vec3 &a, const Vec3 &b) {
    EXPECT_NEAR(a.x, b.x, 1e-5f);
    EXPECT_NEAR(a.y, b.y, 1e-5f);
    EXPECT_NEAR(a.z, b.z, 1e-5f);
}

}  // namespace

TEST(XmlTree, ParsesAllSharedScenes) {
    if (!fs::exists(scenes_dir())) GTEST_SKIP() << "no shared scenes at " << scenes_dir();
    struct Expected {
        size_t shapes;
        float fov;
        int width, height;
    };
    std::map<std::string, Expected> expected = {
        {"bathroom", {856, 55, 1024, 1024}},  {"classroom", {79, 60, 1280, 720}},
        {"cornell-box", {8, 19.5f, 1024, 1024}}, {"living-room", {65, 90, 1280, 720}},
        {"staircase", {775, 35, 720, 1280}},  {"veach-ajar", {22, 60, 1280, 720}}};
    for (const char *name : kSceneDirs) {
        SCOPED_TRACE(name);
        auto root = parse_mitsuba_xml((scenes_dir() / name / "scene.xml").string());
        const Expected &x = expected.at(name);
        EXPECT_EQ(root->tag, "scene");
        auto shapes = root->children_with_tag("shape");
        EXPECT_EQ(shapes.size(), x.shapes);
        for (const auto &s : shapes) EXPECT_EQ(s->children_with_tag("bsdf").size(), 1u) << s->id;
        auto sensors = root->children_with_tag("sensor");
        ASSERT_EQ(sensors.size(), 1u);
        EXPECT_FLOAT_EQ(sensors[0]->get_float("fov"), x.fov);
        auto film = sensors[0]->children_with_tag("film").at(0);
        EXPECT_EQ(film->get_int("width"), x.width);
        EXPECT_EQ(film->get_int("height"), x.height);
        EXPECT_EQ(root->children_with_tag("integrator").at(0)->type, "path");
        EXPECT_EQ(sensors[0]->children_with_tag("sampler").at(0)->get_int("sample_count") > 0, true);
    }
}

TEST(XmlTree, DefineOverridesDefault) {
    fs::path cornell = scenes_dir() / "cornell-box" / "scene.xml";
    if (!fs::exists(cornell)) GTEST_SKIP() << "no shared scenes at " << scenes_dir();
    auto root = parse_mitsuba_xml(cornell.string(), {{"resx", "320"}, {"spp", "4"}});
    auto sensor = root->children_with_tag("sensor").at(0);
    EXPECT_EQ(sensor->children_with_tag("film").at(0)->get_int("width"), 320);
    EXPECT_EQ(sensor->children_with_tag("film").at(0)->get_int("height"), 1024);
    EXPECT_EQ(sensor->children_with_tag("sampler").at(0)->get_int("sample_count"), 4);
    // A shape's bsdf is the node declared with the referenced id; the light has an area emitter.
    auto light = root->children_with_tag("shape").back();
    EXPECT_EQ(light->id, "Light");
    EXPECT_EQ(light->children_with_tag("bsdf").at(0)->id, "LightBSDF");
    Color radiance = light->children_with_tag("emitter").at(0)->get_rgb("radiance");
    expect_near(radiance, Vec3(17, 12, 4));
}

TEST(XmlTree, SubstitutesParameters) {
    TempDir tmp;
    std::string path = tmp.write("s.xml", scene(R"(
  <default name="res" value="7"/>
  <default name="resx" value="64"/>
  <default name="g" value="0.25"/>
  <integrator type="$kind"><integer name="max_depth" value="$res"/></integrator>
  <sensor type="perspective"><film type="hdrfilm">
    <integer name="width" value="$resx"/>
    <string name="label" value="cost \$5 at $res"/>
    <rgb name="tint" value="$g, $g, 1"/>
  </film></sensor>
)"));
    auto root = parse_mitsuba_xml(path, {{"kind", "volpath"}, {"res", "9"}});
    auto integrator = root->children_with_tag("integrator").at(0);
    EXPECT_EQ(integrator->type, "volpath");
    EXPECT_EQ(integrator->get_int("max_depth"), 9);  // -D wins over <default>
    auto film = root->children_with_tag("sensor").at(0)->children_with_tag("film").at(0);
    EXPECT_EQ(film->get_int("width"), 64);  // "$resx" is not "$res" followed by "x"
    EXPECT_EQ(film->get_string("label"), "cost $5 at 9");
    expect_near(film->get_rgb("tint"), Vec3(0.25f, 0.25f, 1));
}

TEST(XmlTree, RefsShareOneNode) {
    TempDir tmp;
    std::string path = tmp.write("s.xml", scene(R"(
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.8"/></bsdf>
  <shape type="sphere"><ref id="white"/></shape>
  <shape type="sphere"><ref name="bsdf" id="white"/><ref id="later"/></shape>
  <bsdf type="bumpmap"><bsdf type="conductor" id="later"/></bsdf>
  <alias id="white" as="snow"/>
  <shape type="cube"><ref id="snow"/></shape>
)"));
    auto root = parse_mitsuba_xml(path);
    auto shapes = root->children_with_tag("shape");
    ASSERT_EQ(shapes.size(), 3u);
    auto white = root->children_with_tag("bsdf").at(0);
    EXPECT_EQ(shapes[0]->children.at(0), white);
    EXPECT_EQ(shapes[1]->child("bsdf"), white);
    EXPECT_EQ(shapes[1]->children.at(1)->type, "conductor");  // forward reference to a nested object
    EXPECT_EQ(shapes[2]->children.at(0), white);
    expect_near(white->get_rgb("reflectance"), Vec3(0.8f));
}

TEST(XmlTree, ComposesTransformsInOrder) {
    TempDir tmp;
    std::string path = tmp.write("s.xml", scene(R"(
  <shape type="cube">
    <transform name="to_world">
      <translate x="1" y="2" z="3"/>
      <scale value="2"/>
    </transform>
  </shape>
  <shape type="cube">
    <transform name="to_world">
      <scale value="2, 2, 2"/>
      <translate value="1 2 3"/>
      <rotate z="1" angle="90"/>
    </transform>
  </shape>
  <shape type="cube">
    <transform name="to_world"><matrix value="1 0 0 7  0 1 0 8  0 0 1 9  0 0 0 1"/></transform>
  </shape>
  <sensor type="perspective">
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
  </sensor>
)"));
    auto root = parse_mitsuba_xml(path);
    auto shapes = root->children_with_tag("shape");
    // Each step applies after the previous ones: translate, then scale.
    expect_near(shapes[0]->get_transform("to_world").point(Vec3(1, 0, 0)), Vec3(4, 4, 6));
    // scale, translate, then a 90 degree turn about z: (1,0,0) -> (2,0,0) -> (3,2,3) -> (-2,3,3).
    expect_near(shapes[1]->get_transform("to_world").point(Vec3(1, 0, 0)), Vec3(-2, 3, 3));
    expect_near(shapes[2]->get_transform("to_world").point(Vec3(0, 0, 0)), Vec3(7, 8, 9));  // row-major
    Transform cam = root->children_with_tag("sensor").at(0)->get_transform("to_world");
    expect_near(cam.point(Vec3(0, 0, 0)), Vec3(0, 0, 5));
    expect_near(cam.vector(Vec3(0, 0, 1)), Vec3(0, 0, -1));  // looks down +z in camera space
    expect_near(cam.vector(Vec3(0, 1, 0)), Vec3(0, 1, 0));
    // An absent transform is the identity.
    expect_near(shapes[0]->get_transform("to_uv").point(Vec3(1, 2, 3)), Vec3(1, 2, 3));
}

TEST(XmlTree, TypedValuesAndGetters) {
    TempDir tmp;
    std::string path = tmp.write("s.xml", scene(R"(
  <bsdf type="test" name="outer">
    <float name="f" value="1.5e-1"/>
    <integer name="i" value="-3"/>
    <boolean name="b" value="True"/>
    <string name="s" value="models/a.obj"/>
    <rgb name="grey" value="0.5"/>
    <spectrum name="flat" value="0.3"/>
    <vector name="dir" x="1" y="2" z="3"/>
    <point name="pos" value="4 5 6"/>
    <texture type="bitmap" name="reflectance"><string name="filename" value="t.png"/></texture>
  </bsdf>
)"));
    auto root = parse_mitsuba_xml(path);
    auto b = root->children.at(0);
    EXPECT_EQ(b->name, "outer");
    EXPECT_FLOAT_EQ(b->get_float("f"), 0.15f);
    EXPECT_FLOAT_EQ(b->get_float("i"), -3.f);  // integers are accepted as floats
    EXPECT_EQ(b->get_int("i"), -3);
    EXPECT_TRUE(b->get_bool("b"));
    EXPECT_EQ(b->get_string("s"), "models/a.obj");
    expect_near(b->get_rgb("grey"), Vec3(0.5f));
    expect_near(b->get_rgb("flat"), Vec3(0.3f));
    expect_near(b->get_rgb("f"), Vec3(0.15f));  // a float is a grey colour
    expect_near(b->get_vector("dir"), Vec3(1, 2, 3));
    expect_near(b->get_vector("pos"), Vec3(4, 5, 6));
    EXPECT_FLOAT_EQ(b->get_float("missing", 2.f), 2.f);
    ASSERT_TRUE(b->child("reflectance"));
    EXPECT_EQ(b->child("reflectance")->type, "bitmap");
    EXPECT_EQ(b->child("nothing"), nullptr);
    EXPECT_EQ(b->resolve_path("models/a.obj"), (tmp.dir / "models/a.obj").lexically_normal().string());
    EXPECT_EQ(b->resolve_path("/abs/x.obj"), "/abs/x.obj");
    EXPECT_TRUE(b->unused_properties().empty());

    expect_error([&] { b->get_int("f"); }, path, 4, "property \"f\"");
    expect_error([&] { b->get_string("grey"); }, path, 8, "is rgb, expected string");
    expect_error([&] { b->get_bool("nope"); }, path, 3, "missing required property \"nope\"");
}

TEST(XmlTree, ReportsUnusedProperties) {
    TempDir tmp;
    std::string path = tmp.write("s.xml", scene(R"(<bsdf type="diffuse"><float name="alpah" value="1"/><float name="a" value="1"/></bsdf>)"));
    auto b = parse_mitsuba_xml(path)->children.at(0);
    b->get_float("a");
    EXPECT_EQ(b->unused_properties(), std::vector<std::string>{"alpah"});
}

TEST(XmlTree, IncludesFilesRelativeToTheIncludingFile) {
    TempDir tmp;
    tmp.write("parts/shapes.xml", scene(R"(<shape type="sphere" id="ball"><ref id="red"/></shape>)"));
    tmp.write("parts/one.xml", R"(<bsdf version="3.0.0" type="diffuse" id="blue"/>)");
    std::string path = tmp.write("s.xml", scene(R"(
  <bsdf type="diffuse" id="red"/>
  <include filename="parts/shapes.xml"/>
  <shape type="cube"><include name="bsdf" filename="parts/one.xml"/></shape>
)"));
    auto root = parse_mitsuba_xml(path);
    auto shapes = root->children_with_tag("shape");
    ASSERT_EQ(shapes.size(), 2u);
    EXPECT_EQ(shapes[0]->id, "ball");
    EXPECT_EQ(shapes[0]->children.at(0)->id, "red");
    EXPECT_EQ(shapes[1]->child("bsdf")->id, "blue");
    EXPECT_EQ(shapes[0]->line, 2);
    EXPECT_NE(shapes[0]->file.find("shapes.xml"), std::string::npos);
    // Files named in an included file resolve against the main scene's folder, as in Mitsuba.
    EXPECT_EQ(shapes[0]->resolve_path("x.obj"), (tmp.dir / "x.obj").lexically_normal().string());
}

// A nested <include> is looked for as Mitsuba's file resolver finds it: beside the including file, then
// beside the files that included that one (innermost first), then in the <path> folders and the scene's
// folder (the render suite's participating_media/include/test-scene-base.xml includes
// "include/preamble.xml", which only the scene's folder has).
TEST(XmlTree, NestedIncludesFallBackToIncludersPathFoldersAndSceneFolder) {
    TempDir tmp;
    tmp.write("inc/base.xml", scene(R"(
  <include filename="inc/pre.xml"/><include filename="frag.xml"/><include filename="near.xml"/>
  <include filename="deeper/d.xml"/>)"));
    tmp.write("inc/pre.xml", scene(R"(<bsdf type="diffuse" id="pre"/>)"));
    tmp.write("common/frag.xml", scene(R"(<bsdf type="diffuse" id="frag"/>)"));
    tmp.write("inc/near.xml", scene(R"(<bsdf type="diffuse" id="near_beside"/>)"));
    tmp.write("near.xml", scene(R"(<bsdf type="diffuse" id="near_scene"/>)"));
    tmp.write("inc/deeper/d.xml", scene(R"(<include filename="up.xml"/>)"));
    tmp.write("inc/up.xml", scene(R"(<bsdf type="diffuse" id="up"/>)"));
    std::string path = tmp.write("s.xml", scene(R"(<path value="common"/><include filename="inc/base.xml"/>)"));
    std::vector<std::string> ids;
    for (const auto &b : parse_mitsuba_xml(path)->children_with_tag("bsdf")) ids.push_back(b->id);
    EXPECT_EQ(ids, (std::vector<std::string>{"pre", "frag", "near_beside", "up"}));
    // Found nowhere: the error names the file as looked for beside the including file.
    tmp.write("inc/lost.xml", scene(R"(<include filename="gone.xml"/>)"));
    try {
        parse_mitsuba_xml(tmp.write("t.xml", scene(R"(<include filename="inc/lost.xml"/>)")));
        FAIL() << "expected an error";
    } catch (const SceneError &e) {
        EXPECT_NE(std::string(e.what()).find((tmp.dir / "inc/gone.xml").string()), std::string::npos) << e.what();
    }
}

// <path value="..."/> adds a folder (relative to the file naming it) that files are looked for in first,
// the last added first, then the scene's folder; Mitsuba 3's render suite uses it in 39 of its 41 scenes.
TEST(XmlTree, PathElementsAddSearchFolders) {
    TempDir tmp;
    tmp.write("meshes/a.obj", "v 0 0 0\n");
    tmp.write("more/a.obj", "v 0 0 0\n");
    tmp.write("more/b.obj", "v 0 0 0\n");
    tmp.write("c.obj", "v 0 0 0\n");
    std::string path = tmp.write("s.xml", scene(R"(
  <shape type="obj"><string name="filename" value="a.obj"/></shape>
  <path value="more"/>
  <path value="meshes"/>
)"));
    auto root = parse_mitsuba_xml(path);
    auto shape = root->children_with_tag("shape").at(0);
    // Declared after the shape, still searched (as in Mitsuba, which resolves files once the scene is read).
    EXPECT_EQ(shape->resolve_path("a.obj"), (tmp.dir / "meshes/a.obj").lexically_normal().string());
    EXPECT_EQ(shape->resolve_path("b.obj"), (tmp.dir / "more/b.obj").lexically_normal().string());
    EXPECT_EQ(shape->resolve_path("c.obj"), (tmp.dir / "c.obj").lexically_normal().string());
    // Found nowhere: the scene's folder, which the loader's "cannot open" message then names.
    EXPECT_EQ(shape->resolve_path("d.obj"), (tmp.dir / "d.obj").lexically_normal().string());
    EXPECT_THROW(parse_mitsuba_xml(tmp.write("bad.xml", scene(R"(<path value=""/>)"))), std::runtime_error);
    EXPECT_THROW(parse_mitsuba_xml(tmp.write("bad2.xml", scene(R"(<path/>)"))), std::runtime_error);
}

TEST(XmlTree, ErrorsNameFileAndLine) {
    TempDir tmp;
    auto check = [&](const std::string &body, int line, const std::string &needle) {
        std::string path = tmp.write("e.xml", scene(body));
        expect_error([&] { parse_mitsuba_xml(path); }, path, line, needle);
    };
    check("<shape type=\"cube\">\n<float name=\"x\" value=\"1\">\n</shape>\n", 4, "malformed XML");
    check("<shape type=\"cube\">\n  <ref id=\"nobody\"/>\n</shape>\n", 3, "unknown id \"nobody\"");
    check("<integrator type=\"path\">\n<integer name=\"max_depth\" value=\"$depth\"/></integrator>\n", 3,
          "undefined parameter $depth");
    check("<sensor type=\"perspective\">\n\n<float name=\"fov\" value=\"4O\"/></sensor>\n", 4,
          "could not parse floating point value \"4O\"");
    check("<shape type=\"cube\"><integer name=\"n\" value=\"1.5\"/></shape>\n", 2, "could not parse integer");
    check("<shape type=\"cube\"/>\n<widget type=\"x\"/>\n", 3, "unknown element <widget>");
    check("<shape>\n</shape>\n", 2, "missing required attribute \"type\"");
    check("<shape type=\"cube\"><float name=\"a\" value=\"1\" extra=\"2\"/></shape>\n", 2, "unexpected attribute \"extra\"");
    check("<shape type=\"cube\">\n<float name=\"a\" value=\"1\"/>\n<float name=\"a\" value=\"2\"/></shape>\n", 4,
          "specified more than once");
    check("<bsdf type=\"a\" id=\"x\"/>\n<bsdf type=\"b\" id=\"x\"/>\n", 3, "duplicate id \"x\"");
    check("<bsdf type=\"twosided\" id=\"loop\">\n<ref id=\"loop\"/></bsdf>\n", 2, "contains itself");
    check("<shape type=\"cube\"><transform name=\"to_world\">\n<rotate angle=\"90\"/></transform></shape>\n", 3,
          "axis cannot be zero");
    check("<shape type=\"cube\"><transform name=\"to_world\">\n<matrix value=\"1 2 3\"/></transform></shape>\n", 3,
          "9 or 16 values");
    check("<shape type=\"cube\"><rgb name=\"c\" value=\"1 2\"/></shape>\n", 2, "one or three values");
    check("<shape type=\"cube\">\n<include filename=\"nowhere.xml\"/></shape>\n", 3, "not found");

    std::string old = tmp.write("old.xml", "<scene version=\"0.5.0\"/>\n");
    expect_error([&] { parse_mitsuba_xml(old); }, old, 1, "not supported");
    std::string missing = (tmp.dir / "absent.xml").string();
    try {
        parse_mitsuba_xml(missing);
        ADD_FAILURE() << "missing file accepted";
    } catch (const SceneError &e) {
        EXPECT_EQ(std::string(e.what()).rfind(missing + ":", 0), 0u) << e.what();
    }
}

// A scene file must not choose how deep the loader recurses: a million nested objects, and chains of <ref>s
// too long in either order of the file, are errors at a line, not a stack overflow; a chain of 60 loads.
TEST(XmlTree, NestingIsBoundedWhateverTheFile) {
    TempDir tmp;
    constexpr int kNested = 1000000;
    std::string deep = "<scene version=\"3.0.0\">\n";
    deep.reserve(size_t(kNested) * 32);
    for (int i = 0; i < kNested; ++i) deep += "<bsdf type=\"twosided\">";
    for (int i = 0; i < kNested; ++i) deep += "</bsdf>";
    deep += "\n</scene>\n";
    const std::string deep_path = tmp.write("deep.xml", deep);
    expect_error([&] { parse_mitsuba_xml(deep_path); }, deep_path, 2, "nested more than 100 deep");

    auto chain = [](int n, bool forward) {  // bsdf i refs bsdf i - 1; forward: each defined before its use
        std::vector<std::string> lines;
        for (int i = 0; i < n; ++i)
            lines.push_back(i == 0 ? "<bsdf type=\"diffuse\" id=\"b0\"/>"
                                   : "<bsdf type=\"twosided\" id=\"b" + std::to_string(i) + "\"><ref id=\"b" +
                                         std::to_string(i - 1) + "\"/></bsdf>");
        if (!forward) std::reverse(lines.begin(), lines.end());
        std::string body = "<shape type=\"sphere\"><ref id=\"b" + std::to_string(n - 1) + "\"/></shape>\n";
        for (const std::string &l : lines) body += l + "\n";
        return scene(body);
    };
    for (bool forward : {true, false}) {
        const std::string path = tmp.write(forward ? "chain.xml" : "reversed.xml", chain(100000, forward));
        try {
            parse_mitsuba_xml(path);
            ADD_FAILURE() << "a chain of 100000 <ref>s loaded";
        } catch (const SceneError &e) {
            EXPECT_NE(std::string(e.what()).find("through <ref>s, more than 100 deep"), std::string::npos) << e.what();
            EXPECT_GT(e.line, 1);
        }
    }
    const std::string ok = tmp.write("ok.xml", chain(60, false));
    const auto root = parse_mitsuba_xml(ok);
    const XmlNode *node = root->children.at(0).get();  // the sphere, then its BSDF 60 deep
    int depth = 0;
    while (!node->children.empty()) node = node->children[0].get(), ++depth;
    EXPECT_EQ(depth, 60);
}

// <spectrum>: pairs, a .spd file (found as other files are) and a constant, converted as Mitsuba 3's RGB
// variants convert them (their values against Mitsuba's: tests/python/test_spectrum_vs_mitsuba.py): a
// reflectance under D65 (a flat 1 is white, clamped to [0, 1]), an emitter's as emission (a flat 1 is
// equal-energy light, purple-ish in sRGB); bad ones are errors at their line.
TEST(XmlTree, SpectraBecomeRgbAsMitsubasRgbVariantsMakeThem) {
    TempDir tmp;
    tmp.write("flat.spd", "# flat\n360 1\n\n830 1\n");
    std::string path = tmp.write("s.xml", scene(R"(<bsdf type="diffuse" id="b"><spectrum name="r" value="360:1, 830:1"/>
  <spectrum name="f" filename="flat.spd"/><spectrum name="c" value="0.5"/><spectrum name="hot" value="550:3, 600:5"/>
  <spectrum name="eta" value="550:3, 600:5"/></bsdf>
<emitter type="constant" id="e"><spectrum name="r" value="360:1, 830:1"/><spectrum name="c" value="0.5"/></emitter>
)"));
    auto root = parse_mitsuba_xml(path);
    const XmlNode &b = *root->children.at(0), &e = *root->children.at(1);
    expect_near(b.get_rgb("r"), Vec3(0.998985f, 0.998874f, 0.998802f));  // Mitsuba 3.9.1's values
    expect_near(b.get_rgb("f"), b.get_rgb("r"));
    expect_near(b.get_rgb("c"), Vec3(0.5f));
    expect_near(b.get_rgb("hot"), Vec3(1.f, 1.f, 0.f));
    expect_near(b.get_unbounded_rgb("eta", Vec3(0.f)), Vec3(2.452148f, 1.486868f, 0.f));
    expect_near(e.get_rgb("r"), Vec3(1.204884f, 0.948228f, 0.909267f));
    expect_near(e.get_rgb("c"), Vec3(0.602397f, 0.474146f, 0.454458f));  // 0.5 x XYZ (1, 1, 1) in sRGB

    auto check = [&](const std::string &body, const std::string &needle) {
        std::string p = tmp.write("e.xml", scene("<bsdf type=\"diffuse\">\n" + body + "</bsdf>\n"));
        expect_error([&] { parse_mitsuba_xml(p); }, p, 3, needle);
    };
    check("<spectrum name=\"r\" value=\"500:0.1, 400:0.2\"/>", "must increase");
    check("<spectrum name=\"r\" value=\"500:0.1\"/>", "at least two");
    check("<spectrum name=\"r\" value=\"500:0.1, 600\"/>", "not a wavelength:value pair");
    check("<spectrum name=\"r\" value=\"400:x, 600:1\"/>", "could not parse spectrum value \"x\"");
    check("<spectrum name=\"r\" filename=\"none.spd\"/>", "cannot open spectrum file");
    check("<spectrum name=\"r\" value=\"1\" filename=\"flat.spd\"/>", "either");
    tmp.write("bad.spd", "400 1\n500 1 2\n");
    check("<spectrum name=\"r\" filename=\"bad.spd\"/>", "line 2");
}
