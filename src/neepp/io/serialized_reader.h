// Mitsuba's `.serialized` meshes, read the way Mitsuba 3's `serialized` shape reads them.
#pragma once
#include <string>
#include "neepp/io/mesh_data.h"

namespace neepp {

// The mesh number `shape_index` of the file (0: the first). Versions 3 and 4 of the format, what
// Mitsuba 0.x and Mitsuba 3 up to 3.9 write: a little-endian header (0x041C, version), then per
// mesh a zlib stream of flags, name (version 4), counts, positions, optional normals, uvs and colours
// (colours are skipped, as Mitsuba does), in single or double precision, and the triangles' indices;
// the file ends with a table of each mesh's offset and their count. Texture v is not flipped. Throws
// SceneError naming the path on a missing, truncated or corrupt file, another version, or a
// shape_index out of range.
MeshData read_serialized(const std::string &path, int shape_index = 0);

}  // namespace neepp
