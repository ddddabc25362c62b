// The .vdb reader: a sparse float grid copied densely over its active voxels' box (inactive voxels inside
// it at the background), placed by the grid's transform with texel centres on voxel centres; which grid
// is read by default; and every kind of bad file or grid refused with the file's name.
#include <gtest/gtest.h>
#include <cmath>

#include "common/temp_dir.h"
#include "common/vdb_writer.h"
#include "neepp/io/scene_error.h"
#include "neepp/io/vdb_reader.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// value = 1 + x' + 10 y' + 100 z' at voxel (x, y, z), x' = x - lo.x etc.: every texel says where it came from.
float ramp(int x, int y, int z) { return float(1 + (x + 2) + 10 * (y - 3) + 100 * z); }

// The voxels (-2..1, 3..4, 0..1): 4 x 2 x 2, voxel size 0.5, voxel (0, 0, 0) centred on (1, 2, 3).
openvdb::FloatGrid::Ptr ramp_grid(const std::string &name = "density") {
    return float_grid(name, openvdb::Coord(-2, 3, 0), openvdb::Coord(1, 4, 1), ramp, 0.5, openvdb::Vec3d(1, 2, 3));
}

// The message read_vdb_grid throws for the file (empty when it reads it).
std::string error_of(const std::string &path, const std::string &grid = "", uint64_t max_voxels = kMaxVdbDenseVoxels) {
    try {
        read_vdb_grid(path, grid, max_voxels);
    } catch (const SceneError &e) {
        EXPECT_EQ(e.file, path);
        return e.what();
    }
    return "";
}

}  // namespace

TEST(VdbReader, CopiesTheActiveBoxDenselyAndPlacesItByTheGridsTransform) {
    TempDir tmp;
    const std::string path = (tmp.dir / "ramp.vdb").string();
    auto grid = ramp_grid();
    grid->tree().setValueOff(openvdb::Coord(0, 4, 1), 0.f);  // inactive inside the box: the background
    write_vdb(path, {grid});
    const VdbGrid g = read_vdb_grid(path);
    EXPECT_EQ(g.name, "density");
    ASSERT_EQ(g.grid.size[0], 4u);
    ASSERT_EQ(g.grid.size[1], 2u);
    ASSERT_EQ(g.grid.size[2], 2u);
    EXPECT_EQ(g.grid.channels, 1u);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x)
                EXPECT_EQ(g.grid.at(x, y, z), x == 2 && y == 1 && z == 1 ? 0.f : ramp(x - 2, y + 3, z)) << x << y << z;
    // Texel (i, j, k)'s centre, (i + 0.5) / n, lands on voxel (i - 2, j + 3, k)'s centre: (1, 2, 3) + 0.5 * voxel.
    const Vec3 centre = g.unit_to_world.point(Vec3(3.5f / 4, 0.5f / 2, 1.5f / 2));
    EXPECT_NEAR(centre.x, 1 + 0.5f * 1, 1e-6f);
    EXPECT_NEAR(centre.y, 2 + 0.5f * 3, 1e-6f);
    EXPECT_NEAR(centre.z, 3 + 0.5f * 1, 1e-6f);
    // The bounds are the edge voxels' outer faces: voxels -2.5..1.5, 2.5..4.5, -0.5..1.5 of 0.5 from (1, 2, 3).
    EXPECT_NEAR(g.grid.bounds.lo.x, 1 - 1.25f, 1e-6f);
    EXPECT_NEAR(g.grid.bounds.lo.y, 2 + 1.25f, 1e-6f);
    EXPECT_NEAR(g.grid.bounds.lo.z, 3 - 0.25f, 1e-6f);
    EXPECT_NEAR(g.grid.bounds.hi.x, 1 + 0.75f, 1e-6f);
    EXPECT_NEAR(g.grid.bounds.hi.y, 2 + 2.25f, 1e-6f);
    EXPECT_NEAR(g.grid.bounds.hi.z, 3 + 0.75f, 1e-6f);
}

TEST(VdbReader, ARotatedScaledTransformIsKeptWhole) {
    TempDir tmp;
    const std::string path = (tmp.dir / "rotated.vdb").string();
    auto grid = float_grid("smoke", openvdb::Coord(0), openvdb::Coord(1, 0, 0), [](int x, int, int) { return float(x + 1); });
    auto xf = openvdb::math::Transform::createLinearTransform(2.0);
    xf->postRotate(openvdb::math::pi<double>() / 2, openvdb::math::Z_AXIS);  // x -> y
    grid->setTransform(xf);
    write_vdb(path, {grid});
    const VdbGrid g = read_vdb_grid(path);  // the only float grid, though not "density"
    EXPECT_EQ(g.name, "smoke");
    // Texel 1 (centre at u = 0.75) is voxel (1, 0, 0), where OpenVDB puts it: scaled by 2, turned off the x axis;
    // the corners of the unit cube are the box's outer faces, half a voxel before voxel 0 and after voxel 1.
    const openvdb::Vec3d voxel = xf->indexToWorld(openvdb::Vec3d(1, 0, 0));
    ASSERT_GT(std::abs(voxel.y()), 1.9);
    for (const auto &[u, index] : {std::pair{Vec3(0.75f, 0.5f, 0.5f), openvdb::Vec3d(1, 0, 0)},
                                   std::pair{Vec3(0.f), openvdb::Vec3d(-0.5)}, std::pair{Vec3(1.f), openvdb::Vec3d(1.5, 0.5, 0.5)}}) {
        const Vec3 p = g.unit_to_world.point(u);
        const openvdb::Vec3d w = xf->indexToWorld(index);
        EXPECT_NEAR(p.x, w.x(), 1e-5);
        EXPECT_NEAR(p.y, w.y(), 1e-5);
        EXPECT_NEAR(p.z, w.z(), 1e-5);
    }
    EXPECT_EQ(g.grid.at(1, 0, 0), 2.f);
}

TEST(VdbReader, ChoosesDensityThenTheOnlyFloatGridThenTheNamedOne) {
    TempDir tmp;
    const std::string several = (tmp.dir / "several.vdb").string();
    auto vel = openvdb::Vec3SGrid::create();
    vel->setName("vel");
    vel->tree().setValueOn(openvdb::Coord(0), openvdb::Vec3s(1, 0, 0));
    auto temperature = float_grid("temperature", openvdb::Coord(0), openvdb::Coord(0), [](int, int, int) { return 7.f; });
    write_vdb(several, {vel, temperature, ramp_grid()});
    EXPECT_EQ(read_vdb_grid(several).name, "density");
    const VdbGrid t = read_vdb_grid(several, "temperature");
    EXPECT_EQ(t.name, "temperature");
    EXPECT_EQ(t.grid.at(0, 0, 0), 7.f);
    // No "density" and two float grids: which one is meant cannot be guessed.
    const std::string two = (tmp.dir / "two.vdb").string();
    write_vdb(two, {temperature, ramp_grid("heat")});
    const std::string e = error_of(two);
    EXPECT_NE(e.find("no grid named \"density\" and 2 float grids"), std::string::npos) << e;
    EXPECT_NE(e.find("(its grids: \"heat\" (float), \"temperature\" (float))"), std::string::npos) << e;
    // A double grid is read as floats.
    const std::string dbl = (tmp.dir / "double.vdb").string();
    auto d = openvdb::DoubleGrid::create(0.0);
    d->setName("density");
    d->tree().setValueOn(openvdb::Coord(5, 5, 5), 0.25);
    write_vdb(dbl, {d});
    EXPECT_EQ(read_vdb_grid(dbl).grid.at(0, 0, 0), 0.25f);
}

TEST(VdbReader, RefusesBadFilesAndGridsNamingTheFile) {
    TempDir tmp;
    EXPECT_NE(error_of((tmp.dir / "missing.vdb").string()).find("cannot read the .vdb file"), std::string::npos);
    const std::string text = tmp.write("text.vdb", "not a vdb file at all, just some text");
    EXPECT_NE(error_of(text).find("cannot read the .vdb file"), std::string::npos) << error_of(text);

    const std::string path = (tmp.dir / "grids.vdb").string();
    auto vel = openvdb::Vec3SGrid::create();
    vel->setName("vel");
    vel->tree().setValueOn(openvdb::Coord(0), openvdb::Vec3s(1, 0, 0));
    auto flags = openvdb::Int32Grid::create(0);
    flags->setName("flags");
    flags->tree().setValueOn(openvdb::Coord(0), 3);
    auto sdf = float_grid("surface", openvdb::Coord(0), openvdb::Coord(1), [](int, int, int) { return -0.5f; });
    sdf->setGridClass(openvdb::GRID_LEVEL_SET);
    auto empty = openvdb::FloatGrid::create(0.f);
    empty->setName("empty");
    write_vdb(path, {vel, flags, sdf, empty, ramp_grid()});

    const std::string none = error_of(path, "smoke");
    EXPECT_NE(none.find("no grid named \"smoke\"; its grids: \"density\" (float), \"empty\" (float), \"flags\" (int32), "
                        "\"surface\" (float), \"vel\" (vec3s)"),
              std::string::npos)
        << none;
    EXPECT_NE(error_of(path, "vel").find("\"vel\" (vec3s) holds vectors"), std::string::npos);
    EXPECT_NE(error_of(path, "flags").find("\"flags\" (int32) does not hold floats"), std::string::npos);
    EXPECT_NE(error_of(path, "surface").find("is a level set"), std::string::npos);
    EXPECT_NE(error_of(path, "empty").find("has no active voxels"), std::string::npos);
    // The cap on the dense copy (4 x 2 x 2 = 16 voxels here against a cap of 15), checked before the tree is read
    // where the writer recorded the active box in the grid's metadata, as OpenVDB's own writer does.
    openvdb::io::File file(path);
    file.open(false);
    EXPECT_TRUE(file.readGridMetadata("density")->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX));
    const std::string big = error_of(path, "density", 15);
    EXPECT_NE(big.find("span 4 x 2 x 2 = 16 voxels, more than the 15"), std::string::npos) << big;
    EXPECT_EQ(error_of(path, "density", 16), "");
}
