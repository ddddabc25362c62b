// Visibility-map files: round trip, and refusal (with a clear error) of damaged files, files of another
// scene or grid; a render that loads the map it saved is identical to the render that built it.
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include "neepp/integrators/path.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/map_file.h"
#include "neepp/visibility/neepp_shadow_rays.h"
#include "test_scenes.h"
#include "visibility_test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

std::string temp_file(const std::string &name) {
    auto dir = std::filesystem::path(write_temp_scene("", "unused.xml")).parent_path();
    return (dir / name).string();
}

std::string error_of(const std::function<void()> &f) {
    try {
        f();
    } catch (const std::runtime_error &e) {
        return e.what();
    }
    return "";
}

struct Built {
    std::unique_ptr<Scene> scene;
    NeeppShadowRays tester;
};

std::unique_ptr<Built> build(const std::string &xml, const std::string &map_file, int voxels = 8) {
    NeeppOptions o;
    o.voxels = voxels;
    o.samples_per_pair = 8;
    o.map_file = map_file;
    auto b = std::make_unique<Built>(Built{load_scene(write_temp_scene(xml)), NeeppShadowRays(o)});
    b->tester.prepare(*b->scene);
    return b;
}

TEST(MapFile, RoundTrip) {
    std::string file = temp_file("rooms.nvm");
    auto a = build(two_rooms_xml(), file);
    ASSERT_TRUE(std::filesystem::exists(file));
    EXPECT_EQ(a->tester.statistics()["map"]["source"], "built");
    EXPECT_GT(a->tester.map().known_pairs(), 100u);
    auto b = build(two_rooms_xml(), file);  // exists and matches: loaded, not rebuilt
    EXPECT_EQ(b->tester.statistics()["map"]["source"], "loaded");
    EXPECT_EQ(b->tester.statistics()["map"]["build_shadow_rays"], 0);
    ASSERT_EQ(a->tester.map().pair_count(), b->tester.map().pair_count());
    const auto &da = a->tester.map().data(), &db = b->tester.map().data();
    for (size_t i = 0; i < da.size(); ++i) {
        ASSERT_EQ(da[i].visible, db[i].visible) << "pair " << i;
        ASSERT_EQ(da[i].traced, db[i].traced) << "pair " << i;
    }
    // Direct API, with the counts saturating at 16 bits.
    VisibilityMap m(a->tester.grid().cell_count());
    m.set(0u, 5u, PairCounts{65535, 65535});
    m.set(3u, 3u, PairCounts{0, 1});
    std::string f2 = temp_file("direct.nvm");
    save_visibility_map(f2, a->tester.grid(), m, 42);
    VisibilityMap back = load_visibility_map(f2, a->tester.grid(), 42);
    EXPECT_EQ(back.counts(5, 0).traced, 65535);
    EXPECT_EQ(back.counts(3, 3).traced, 1);
    EXPECT_EQ(back.known_pairs(), 2u);
}

TEST(MapFile, EveryFlippedByteIsRefused) {
    std::string file = temp_file("damaged.nvm");
    auto a = build(two_rooms_xml(), file);
    std::string bytes;
    {
        std::ifstream in(file, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    ASSERT_GT(bytes.size(), 100u);
    // Flip one bit at many positions (header, payload, checksum): each damaged copy must be refused.
    for (size_t pos = 0; pos < bytes.size(); pos += std::max<size_t>(1, bytes.size() / 97)) {
        std::string damaged = bytes;
        damaged[pos] = char(damaged[pos] ^ 0x10);
        std::string f = temp_file("flipped.nvm");
        std::ofstream(f, std::ios::binary).write(damaged.data(), std::streamsize(damaged.size()));
        std::string err = error_of([&] { load_visibility_map(f, a->tester.grid(), scene_fingerprint(*a->scene)); });
        EXPECT_NE(err, "") << "flipped byte " << pos << " was accepted";
        EXPECT_NE(err.find(f), std::string::npos) << "the error must name the file: " << err;
    }
    // Truncated, and not a map at all.
    std::string f = temp_file("short.nvm");
    std::ofstream(f, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() / 2));
    EXPECT_NE(error_of([&] { load_visibility_map(f, a->tester.grid(), scene_fingerprint(*a->scene)); }), "");
    std::ofstream(f, std::ios::binary) << "hello world, this is not a visibility map";
    EXPECT_NE(error_of([&] { load_visibility_map(f, a->tester.grid(), scene_fingerprint(*a->scene)); }).find("magic"),
              std::string::npos);
    // Damaged middle byte through the integrator option: prepare() refuses rather than overwriting.
    std::string damaged = bytes;
    damaged[bytes.size() / 2] = char(damaged[bytes.size() / 2] ^ 1);
    std::ofstream(file, std::ios::binary).write(damaged.data(), std::streamsize(damaged.size()));
    std::string err = error_of([&] { build(two_rooms_xml(), file); });
    EXPECT_NE(err.find("damaged"), std::string::npos) << err;
}

TEST(MapFile, MapOfAnotherSceneOrGridIsRefused) {
    std::string file = temp_file("open.nvm");
    auto a = build(two_rooms_xml(false), file);
    std::string err = error_of([&] { build(two_rooms_xml(true), file); });  // one more box: another scene
    EXPECT_NE(err.find("another scene"), std::string::npos) << err;
    EXPECT_NE(err.find(file), std::string::npos) << err;
    err = error_of([&] { build(two_rooms_xml(false), file, 16); });
    EXPECT_NE(err.find("grid"), std::string::npos) << err;
    // The camera and materials do not change visibility: a map stays valid for another film size.
    EXPECT_EQ(error_of([&] { build(two_rooms_xml(false, 32, 24), file); }), "");
}

TEST(MapFile, RenderWithSavedMapEqualsRenderThatBuiltIt) {
    std::string file = temp_file("render.nvm");
    std::string path = write_temp_scene(two_rooms_xml());
    Options o(OptionMap{{"shadow_rays", "neepp"}, {"visibility_map", file}});
    RenderedImage built = render_scene_file(path, 8, 3, o);
    ASSERT_TRUE(std::filesystem::exists(file));
    RenderedImage loaded = render_scene_file(path, 8, 3, o);
    EXPECT_EQ(built.image.data, loaded.image.data);
    EXPECT_EQ(built.result.counters.shadow_rays, loaded.result.counters.shadow_rays);
}

}  // namespace
