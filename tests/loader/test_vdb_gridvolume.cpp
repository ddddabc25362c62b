// A `gridvolume` whose file is a .vdb, through the loader: a heterogeneous medium's lookups at voxel centres
// and between them, its bounds and majorant, to_world placing the file's world space; the same density as a
// .vol gives the same lookups and the same image; and what the loader refuses, at the volume's line.
#include <gtest/gtest.h>
#include <algorithm>
#include <fmt/core.h>
#include <filesystem>
#include <fstream>
#include "common/vdb_writer.h"
#include "common/volume_grid_writer.h"
#include "neepp/base/interaction.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// Voxels (0..3, 0..1, 0..1) of 0.25, voxel (i, j, k) centred on 0.25 (i, j, k): value 1 + i + 10 j + 100 k,
// so a lookup says where it read. Their box is [-0.125, 0.875] x [-0.125, 0.375]^2.
float ramp(int x, int y, int z) { return float(1 + x + 10 * y + 100 * z); }

std::string write_ramp_vdb(const std::string &dir) {
    const std::string path = dir + "/ramp.vdb";
    write_vdb(path, {float_grid("density", openvdb::Coord(0), openvdb::Coord(3, 1, 1), ramp, 0.25)});
    return path;
}

// The same values as a .vol, its bounds the .vdb's box, placed by use_grid_bbox.
std::string write_ramp_vol(const std::string &dir) {
    VolumeGridFile g;
    g.size[0] = 4, g.size[1] = 2, g.size[2] = 2;
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x) g.values.push_back(ramp(x, y, z));
    g.bounds = {-0.125f, -0.125f, -0.125f, 0.875f, 0.375f, 0.375f};
    const std::string path = dir + "/ramp.vol";
    std::ofstream(path, std::ios::binary) << volume_grid_bytes(g);
    return path;
}

// A scene whose null cube (of half-size 2) holds a heterogeneous medium of sigma_t `volume`, scale 2, lit by a
// constant sky and seen by a 8 x 8 volpath camera.
std::string scene_xml(const std::string &volume) {
    return fmt::format(R"(<scene version="3.0.0">
  <integrator type="volpath"/>
  <sensor type="perspective"><float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0.4,0.1,4" target="0.4,0.1,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film></sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="cube"><transform name="to_world"><scale value="2"/></transform><bsdf type="null"/>
    <medium type="heterogeneous" name="interior"><float name="scale" value="2"/><float name="albedo" value="0.5"/>
      {}</medium></shape>
</scene>)",
                       volume);
}

std::string gridvolume(const std::string &file, const std::string &extra = "") {
    return R"(<volume name="sigma_t" type="gridvolume"><string name="filename" value=")" + file + "\"/>" + extra + "</volume>";
}

const Medium &the_medium(const Scene &scene) {
    for (const auto &shape : scene.shapes())
        if (shape->interior) return *shape->interior;
    throw std::runtime_error("no medium");
}

float sigma_t(const Medium &m, float x, float y, float z) { return m.at(Vec3(x, y, z), Vec3(0, 0, 1)).sigma_t.x; }

std::string dir_of(const std::string &path) { return std::filesystem::path(path).parent_path().string(); }

}  // namespace

TEST(VdbGridVolume, LooksUpVoxelCentresAndTrilinearlyBetween) {
    const std::string dir = dir_of(write_temp_scene(""));
    const auto scene = load_scene(write_temp_scene(scene_xml(gridvolume(write_ramp_vdb(dir)))));
    const Medium &m = the_medium(*scene);
    EXPECT_FLOAT_EQ(sigma_t(m, 0.5f, 0.25f, 0.f), 2 * 13.f);        // voxel (2, 1, 0), times the scale
    EXPECT_FLOAT_EQ(sigma_t(m, 0.375f, 0.f, 0.f), 2 * 2.5f);        // halfway between voxels 1 and 2
    EXPECT_FLOAT_EQ(sigma_t(m, 0.3125f, 0.125f, 0.1875f), 2 * (1 + 1.25f + 5 + 75));
    EXPECT_FLOAT_EQ(m.majorant(Vec3(0, 0, 1)).x, 2 * 114.f);
    // Its bounds: the box of the active voxels, in the file's own coordinates.
    Ray ray;
    ray.o = Vec3(-1.f, 0.1f, 0.1f), ray.d = Vec3(1.f, 0.f, 0.f);
    float t0, t1;
    ASSERT_TRUE(m.overlap(ray, t0, t1));
    EXPECT_FLOAT_EQ(t0, 0.875f);
    EXPECT_FLOAT_EQ(t1, 1.875f);
    ray.o = Vec3(-1.f, 0.4f, 0.1f);  // above the box
    EXPECT_FALSE(m.overlap(ray, t0, t1));
}

TEST(VdbGridVolume, ToWorldPlacesTheFilesWorldSpace) {
    const std::string dir = dir_of(write_temp_scene(""));
    const std::string xml = scene_xml(gridvolume(
        write_ramp_vdb(dir), R"(<transform name="to_world"><scale value="2"/><translate x="-1" y="0" z="0"/></transform>)"));
    const auto scene = load_scene(write_temp_scene(xml));
    const Medium &m = the_medium(*scene);
    // Voxel (2, 1, 0), at (0.5, 0.25, 0) in the file, is at 2 (0.5, 0.25, 0) - (1, 0, 0) in the scene.
    EXPECT_FLOAT_EQ(sigma_t(m, 0.f, 0.5f, 0.f), 2 * 13.f);
    Ray ray;
    ray.o = Vec3(-2.f, 0.2f, 0.2f), ray.d = Vec3(1.f, 0.f, 0.f);
    float t0, t1;
    ASSERT_TRUE(m.overlap(ray, t0, t1));
    EXPECT_FLOAT_EQ(t0, 2 * -0.125f - 1 + 2);
    EXPECT_FLOAT_EQ(t1, 2 * 0.875f - 1 + 2);
}

// The one density as a .vol (placed by use_grid_bbox) and as a .vdb: the same lookups everywhere, and so the
// same image to the bit.
TEST(VdbGridVolume, TheSameDensityAsAVolGivesTheSameLookupsAndImage) {
    const std::string dir = dir_of(write_temp_scene(""));
    const std::string vdb_scene = write_temp_scene(scene_xml(gridvolume(write_ramp_vdb(dir))));
    const std::string vol_scene =
        write_temp_scene(scene_xml(gridvolume(write_ramp_vol(dir), R"(<boolean name="use_grid_bbox" value="true"/>)")));
    const auto a = load_scene(vdb_scene), b = load_scene(vol_scene);
    const Medium &ma = the_medium(*a), &mb = the_medium(*b);
    EXPECT_EQ(ma.majorant(Vec3(0, 0, 1)), mb.majorant(Vec3(0, 0, 1)));
    for (int i = 0; i < 1000; ++i) {
        const Vec3 p(-0.2f + 1.1f * float(i % 10) / 9, -0.2f + 0.6f * float(i / 10 % 10) / 9, -0.2f + 0.6f * float(i / 100) / 9);
        EXPECT_EQ(ma.at(p, Vec3(0, 0, 1)).sigma_t, mb.at(p, Vec3(0, 0, 1)).sigma_t) << p.x << " " << p.y << " " << p.z;
    }
    const auto ia = render_scene_file(vdb_scene, 16, 7, Options(), "volpath").image;
    const auto ib = render_scene_file(vol_scene, 16, 7, Options(), "volpath").image;
    EXPECT_EQ(ia.data, ib.data);
    EXPECT_LT(*std::min_element(ia.data.begin(), ia.data.end()), 0.5f);  // the medium is in the picture, dark
}

TEST(VdbGridVolume, RefusesWhatDoesNotApplyAtTheVolumesLine) {
    const std::string dir = dir_of(write_temp_scene(""));
    const std::string vdb = write_ramp_vdb(dir), vol = write_ramp_vol(dir);
    auto error = [](const std::string &volume) {
        try {
            load_scene(write_temp_scene(scene_xml(volume)));
        } catch (const std::exception &e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const std::string missing = error(gridvolume(vdb, R"(<string name="grid" value="smoke"/>)"));
    EXPECT_NE(missing.find("scene.xml:9:"), std::string::npos) << missing;
    EXPECT_NE(missing.find(vdb + ": the .vdb file has no grid named \"smoke\"; its grids: \"density\" (float)"),
              std::string::npos)
        << missing;
    EXPECT_NE(error(gridvolume(vdb, R"(<boolean name="use_grid_bbox" value="false"/>)")).find("placed by its own transform"),
              std::string::npos);
    EXPECT_NE(error(gridvolume(vol, R"(<string name="grid" value="density"/>)")).find("names a grid of a .vdb file"),
              std::string::npos);
    EXPECT_NE(error(gridvolume(dir + "/absent.vdb")).find("absent.vdb: cannot read the .vdb file"), std::string::npos);
    // A density below 0, refused as in a .vol, naming the file.
    const std::string negative = dir + "/negative.vdb";
    write_vdb(negative, {float_grid("density", openvdb::Coord(0), openvdb::Coord(1), [](int x, int, int) { return x - 0.5f; })});
    const std::string below = error(gridvolume(negative));
    EXPECT_NE(below.find(negative + ": the value at grid point (0, 0, 0) is -0.5"), std::string::npos) << below;
    EXPECT_NE(below.find("are not negative"), std::string::npos) << below;
    // The grid named, and use_grid_bbox="true" (what a .vdb does anyway), are accepted.
    EXPECT_EQ(error(gridvolume(vdb, R"(<string name="grid" value="density"/><boolean name="use_grid_bbox" value="true"/>)")), "");
}
