// Wavefront OBJ meshes, read the way Mitsuba 3's `obj` shape reads them.
#pragma once
#include <string>
#include "neepp/io/mesh_data.h"

namespace neepp {

// All groups and objects merge into one mesh; polygons are fanned into triangles; a vertex is
// emitted once per distinct (position, uv, normal) index triple, in order of first use; texture v
// is flipped (v' = 1 - v). Only v, vt, vn and f lines matter; everything else is ignored.
// Throws SceneError naming the path (and line) when the file is missing or malformed.
MeshData read_obj(const std::string &path);

}  // namespace neepp
