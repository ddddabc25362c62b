// OpenVDB's .vdb files (what Houdini, Blender and most volume tools write; pbrt-v4 reads them, Mitsuba 3
// cannot): one scalar grid of a file, resampled into the dense VolumeGrid that a `gridvolume` looks up.
#pragma once
#include <cstdint>
#include <string>
#include "neepp/io/volume_grid_reader.h"
#include "neepp/math/transform.h"

namespace neepp {

struct VdbGrid {
    std::string name;  // the grid read
    // One channel over the bounding box of the grid's active voxels, x fastest; a voxel of that box that is not
    // active holds what the sparse grid gives there (its background, usually 0). `bounds` is the box's world
    // bounds (axis-aligned around unit_to_world's image of the unit cube).
    VolumeGrid grid;
    // The dense grid's domain, the unit cube (texel centres at (i + 0.5) / n, as a .vol's), to the file's world
    // space: through the box in index space, whose voxel (i, j, k) OpenVDB centres on the point (i, j, k), then
    // through the grid's own transform. A texel's centre lands on its voxel's centre.
    Transform unit_to_world;
};

// The most voxels a grid's dense copy may have: 2^30, 4 GiB of floats (a 1024^3 box). Sparse grids larger
// than that are meant for renderers that look them up sparsely, which neepp does not.
inline constexpr uint64_t kMaxVdbDenseVoxels = uint64_t(1) << 30;

// Reads the float (or double) grid `grid_name` of the file; an empty name chooses "density" if the file has
// one, else its only scalar grid. Throws SceneError naming the path on a missing or malformed file, a grid it
// does not have (listing those it has), a grid of vectors or of another type, a level set, a grid with no
// active voxels, a non-linear (frustum) transform, a box of more than max_voxels voxels or one that does not
// fit in memory.
VdbGrid read_vdb_grid(const std::string &path, const std::string &grid_name = "", uint64_t max_voxels = kMaxVdbDenseVoxels);

}  // namespace neepp
