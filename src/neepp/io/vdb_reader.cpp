// Through libopenvdb (Debian's libopenvdb-dev), the only file of neepp that includes it: OpenVDB's headers
// are heavy, and the library's dependencies (Boost, Blosc, its own TBB use) stay behind this one function.
#include "neepp/io/vdb_reader.h"

#include <new>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include "neepp/io/scene_error.h"

namespace neepp {

namespace {

std::string describe(const openvdb::GridBase &g) { return "\"" + g.getName() + "\" (" + g.valueType() + ")"; }

std::string list_grids(const openvdb::GridPtrVec &grids) {
    std::string s;
    for (const auto &g : grids) s += (s.empty() ? "" : ", ") + describe(*g);
    return s.empty() ? "none" : s;
}

bool is_scalar(const openvdb::GridBase &g) { return g.isType<openvdb::FloatGrid>() || g.isType<openvdb::DoubleGrid>(); }

// The grid the scene names, or the default: "density" (what Houdini, Blender and pbrt-v4 call a fog volume's
// grid), else the file's only scalar grid.
openvdb::GridBase::Ptr choose(const std::string &path, const openvdb::GridPtrVec &grids, const std::string &name) {
    auto named = [&](const std::string &n) -> openvdb::GridBase::Ptr {
        for (const auto &g : grids)
            if (g->getName() == n) return g;
        return nullptr;
    };
    if (!name.empty()) {
        if (auto g = named(name)) return g;
        throw SceneError(path, "the .vdb file has no grid named \"" + name + "\"; its grids: " + list_grids(grids));
    }
    if (auto g = named("density")) return g;
    openvdb::GridPtrVec scalar;
    for (const auto &g : grids)
        if (is_scalar(*g)) scalar.push_back(g);
    if (scalar.size() == 1) return scalar[0];
    throw SceneError(path, "the .vdb file has no grid named \"density\" and " + std::to_string(scalar.size()) +
                               " float grids; name the one to read with <string name=\"grid\" value=\"...\"/> "
                               "(its grids: " + list_grids(grids) + ")");
}

std::string box_string(const openvdb::Coord &dim) {
    return std::to_string(dim.x()) + " x " + std::to_string(dim.y()) + " x " + std::to_string(dim.z());
}

void check_size(const std::string &path, const openvdb::GridBase &g, const openvdb::Coord &dim, uint64_t max_voxels) {
    const uint64_t count = uint64_t(dim.x()) * uint64_t(dim.y()) * uint64_t(dim.z());
    if (count > max_voxels)
        throw SceneError(path, "grid " + describe(g) + ": its active voxels span " + box_string(dim) + " = " +
                                   std::to_string(count) + " voxels, more than the " + std::to_string(max_voxels) +
                                   " a gridvolume's dense copy may have (" + std::to_string(max_voxels * 4 >> 20) +
                                   " MiB): resample it coarser");
}

template <typename GridT>
void copy_to_dense(const GridT &grid, const openvdb::CoordBBox &box, std::vector<float> &values) {
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, values.data());
    openvdb::tools::copyToDense(grid, dense);
}

}  // namespace

VdbGrid read_vdb_grid(const std::string &path, const std::string &grid_name, uint64_t max_voxels) {
    openvdb::initialize();  // registers the grid types; idempotent and thread-safe
    openvdb::io::File file(path);
    openvdb::GridBase::Ptr grid;
    try {
        // Not delay-loaded: the grid is read whole now and copied, so mapping the file would only keep it open.
        file.open(false);
        const openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();
        grid = choose(path, *grids, grid_name);
        if (grid->isType<openvdb::Vec3SGrid>() || grid->isType<openvdb::Vec3DGrid>() || grid->isType<openvdb::Vec3IGrid>())
            throw SceneError(path, "grid " + describe(*grid) +
                                       " holds vectors; a gridvolume reads one float grid of a .vdb file (a density)");
        if (!is_scalar(*grid))
            throw SceneError(path, "grid " + describe(*grid) + " does not hold floats; a gridvolume reads a float grid");
        if (grid->getGridClass() == openvdb::GRID_LEVEL_SET)
            throw SceneError(path, "grid " + describe(*grid) +
                                       " is a level set (signed distances to a surface), not a density (a fog volume)");
        // Writers record the active voxels' box in the metadata: a grid too large is refused before its tree is read.
        const auto lo = grid->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
        const auto hi = grid->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
        if (lo && hi) {
            const openvdb::CoordBBox box(openvdb::Coord(lo->value()), openvdb::Coord(hi->value()));
            if (!box.empty()) check_size(path, *grid, box.dim(), max_voxels);
        }
        grid = file.readGrid(grid->getName());
        file.close();
    } catch (const SceneError &) {
        throw;
    } catch (const std::bad_alloc &) {
        throw SceneError(path, "the .vdb file's grid does not fit in memory");
    } catch (const std::exception &e) {  // openvdb::IoError and the like: a missing, truncated or foreign file
        throw SceneError(path, std::string("cannot read the .vdb file: ") + e.what());
    }
    if (!grid->transform().isLinear())
        throw SceneError(path, "grid " + describe(*grid) + " has a non-linear (" + grid->transform().mapType() +
                                   ") transform; a gridvolume places its grid by an affine one");
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    if (box.empty()) throw SceneError(path, "grid " + describe(*grid) + " has no active voxels");
    const openvdb::Coord dim = box.dim();
    check_size(path, *grid, dim, max_voxels);

    VdbGrid out;
    out.name = grid->getName();
    VolumeGrid &g = out.grid;
    g.size[0] = uint32_t(dim.x()), g.size[1] = uint32_t(dim.y()), g.size[2] = uint32_t(dim.z());
    g.channels = 1;
    try {
        g.values.resize(size_t(dim.x()) * size_t(dim.y()) * size_t(dim.z()));
    } catch (const std::bad_alloc &) {
        throw SceneError(path, "grid " + describe(*grid) + ": its " + box_string(dim) + " dense copy does not fit in memory");
    }
    if (auto f = openvdb::GridBase::grid<openvdb::FloatGrid>(grid))
        copy_to_dense(*f, box, g.values);
    else
        copy_to_dense(*openvdb::GridBase::grid<openvdb::DoubleGrid>(grid), box, g.values);

    // The unit cube to index space: its corners on the outer faces of the box's edge voxels, (min - 1/2) and
    // (max + 1/2), so that texel centres fall on voxel centres. Then to world through the grid's transform, which
    // is affine: the images of a corner and of the three edges from it give its matrix.
    const openvdb::Vec3d origin = box.min().asVec3d() - openvdb::Vec3d(0.5);
    const openvdb::math::Transform &xf = grid->transform();
    const openvdb::Vec3d p0 = xf.indexToWorld(origin);
    Matrix4 m = Matrix4::identity();
    for (int axis = 0; axis < 3; ++axis) {
        openvdb::Vec3d edge(0.0);
        edge[axis] = double(dim[axis]);
        const openvdb::Vec3d column = xf.indexToWorld(origin + edge) - p0;
        for (int row = 0; row < 3; ++row) m.m[row][axis] = float(column[row]);
    }
    for (int row = 0; row < 3; ++row) m.m[row][3] = float(p0[row]);
    try {
        out.unit_to_world = Transform(m);
    } catch (const std::exception &) {
        throw SceneError(path, "grid " + describe(*grid) + " has a singular transform (a voxel of no volume)");
    }
    for (int k = 0; k < 8; ++k)
        g.bounds.expand(out.unit_to_world.point(Vec3(float(k & 1), float(k >> 1 & 1), float(k >> 2 & 1))));
    return out;
}

}  // namespace neepp
