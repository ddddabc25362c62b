// Visibility-map files: a map is expensive to seed and only valid for the geometry and grid it was built
// for, so the file carries everything needed to refuse a wrong one.
//
// Layout (little-endian, as written by this machine):
//   "NEEPPVIS" | u32 version (1) | u32 resolution N | u32 direction bins | 6 × f32 grid bounds (lo, hi)
//   | u64 scene fingerprint | u64 entry count | entries (u32 pair index, u16 visible, u16 traced), pair
//   index strictly increasing | u64 FNV-1a-64 checksum of every byte before it.
// Only known pairs are written (a seeded N = 16 map has ~1e5 of its 8.8 M pairs), so files are small.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include "neepp/io/checksum.h"
#include "neepp/visibility/visibility_map.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

class Scene;

// A hash of what visibility depends on: every shape's geometry (positions, indices, spheres, curves), the
// lights' kinds and the scene bounds. Materials, textures and the camera do not change visibility, so a
// map stays valid when they change.
uint64_t scene_fingerprint(const Scene &scene);

struct MapFileHeader {
    uint32_t version = 0;
    int resolution = 0;
    BBox bounds;
    uint64_t fingerprint = 0;
};

void save_visibility_map(const std::string &path, const VoxelGrid &grid, const VisibilityMap &map, uint64_t fingerprint);

// Reads a map file and checks it: magic, version, checksum, structure, and that it belongs to this grid
// (resolution and bounds) and this scene (fingerprint). Throws std::runtime_error naming the file and
// the mismatch otherwise.
VisibilityMap load_visibility_map(const std::string &path, const VoxelGrid &grid, uint64_t fingerprint);
// The same with the grid the file was written for (its resolution and bounds: the scene's, or those of a
// grid_bounds=shading render, which depend on the camera and cannot be known without the file).
std::pair<VoxelGrid, VisibilityMap> load_visibility_map(const std::string &path, uint64_t fingerprint);

// The same in memory (a render checkpoint carries a map): the file's bytes, and their checked reading,
// whose errors start with `what`.
std::string encode_visibility_map(const VoxelGrid &grid, const VisibilityMap &map, uint64_t fingerprint);
VisibilityMap decode_visibility_map(const std::string &bytes, const std::string &what, const VoxelGrid &grid,
                                    uint64_t fingerprint);
// The same for bytes whose grid is not known beforehand (merging the maps several renders learned): the
// grid they were encoded for comes back with the map.
std::pair<VoxelGrid, VisibilityMap> decode_visibility_map(const std::string &bytes, const std::string &what,
                                                          uint64_t fingerprint);

}  // namespace neepp
