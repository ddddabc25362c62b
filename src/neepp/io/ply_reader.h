// Stanford PLY meshes (ascii, binary_little_endian, binary_big_endian), read the way Mitsuba 3's
// `ply` shape reads them.
#pragma once
#include <string>
#include "neepp/io/mesh_data.h"

namespace neepp {

// Vertex properties x y z, optional nx ny nz, optional u v (or texture_u texture_v, or s t) of any
// scalar type; faces from the `vertex_indices` (or `vertex_index`) list, polygons fanned into
// triangles. Texture v is NOT flipped (Mitsuba's flip_tex_coords defaults to false for PLY). Other
// elements and properties are skipped. Throws SceneError naming the path on a missing, truncated or
// malformed file.
MeshData read_ply(const std::string &path);

}  // namespace neepp
