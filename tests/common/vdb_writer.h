// Writes .vdb files through OpenVDB's own API, for the .vdb reader's and the gridvolume's tests (a test
// that includes this links OpenVDB::openvdb itself: neepp_io keeps it private).
#pragma once
#include <functional>
#include <string>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

namespace neepp::testing {

// A float grid named `name` whose voxels (x, y, z), for each coordinate in [lo, hi], are active and hold
// value(x, y, z); its transform is voxel_size and then origin (the world point of voxel (0, 0, 0)'s centre).
inline openvdb::FloatGrid::Ptr float_grid(const std::string &name, openvdb::Coord lo, openvdb::Coord hi,
                                          const std::function<float(int, int, int)> &value, double voxel_size = 1.0,
                                          openvdb::Vec3d origin = openvdb::Vec3d(0.0)) {
    openvdb::initialize();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName(name);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto xf = openvdb::math::Transform::createLinearTransform(voxel_size);
    xf->postTranslate(origin);
    grid->setTransform(xf);
    auto acc = grid->getAccessor();
    for (int z = lo.z(); z <= hi.z(); ++z)
        for (int y = lo.y(); y <= hi.y(); ++y)
            for (int x = lo.x(); x <= hi.x(); ++x) acc.setValueOn(openvdb::Coord(x, y, z), value(x, y, z));
    return grid;
}

inline void write_vdb(const std::string &path, const openvdb::GridPtrVec &grids) {
    openvdb::initialize();
    openvdb::io::File(path).write(grids);
}

}  // namespace neepp::testing
