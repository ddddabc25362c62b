// Triangle mesh data as read from a file, before any to_world transform is applied, plus the few
// helpers the OBJ, PLY, .serialized and curve readers share.
#pragma once
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include "neepp/io/scene_error.h"
#include "neepp/math/vec.h"

namespace neepp {

// A per-vertex or per-face attribute of a mesh (Mitsuba's "vertex_color", "face_weight"...), read by the
// mesh_attribute texture: dim (1, 3, or 4 with alpha) floats per vertex or per triangle, as stored.
struct MeshAttribute {
    std::string name;  // with its "vertex_" or "face_" prefix
    int dim = 1;
    std::vector<float> values;

    bool per_face() const { return name.rfind("face_", 0) == 0; }
};

struct MeshData {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;  // empty when the file has none; else one per position, unit length or zero
    std::vector<Vec2> uvs;      // empty when the file has none; else one per position
    std::vector<uint32_t> indices;  // three per triangle, in the file's winding order
    std::vector<MeshAttribute> attributes;  // face attributes have one entry per triangle

    size_t triangle_count() const { return indices.size() / 3; }
};

namespace mesh_detail {

// The whole file; what names it in the error when it cannot be opened ("mesh file", "curve file").
inline std::string read_file(const std::string &path, const char *what = "mesh file") {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw SceneError(path, std::string("cannot open ") + what);
    std::ostringstream ss;
    ss << in.rdbuf();
    return std::move(ss).str();
}

// Parses one number at `p` (no leading blanks, '+' allowed) and advances past it. Accepts "nan" and
// "inf" so that the caller can report them as invalid data instead of as a syntax error.
inline bool parse_real(const char *&p, const char *end, double &out) {
    const char *s = p;
    if (s < end && *s == '+') ++s;
    auto [q, ec] = std::from_chars(s, end, out);
    if (ec == std::errc::invalid_argument || q == s) return false;
    if (ec == std::errc::result_out_of_range) {
        // from_chars refuses values that over- or underflow; strtod rounds them to inf or 0 as
        // other readers do, and the finiteness check decides.
        out = std::strtod(std::string(s, q).c_str(), nullptr);
    }
    p = q;
    return true;
}

// Checks what both readers must guarantee and normalizes the normals, as Mitsuba does on load.
inline void finish_mesh(MeshData &m, const std::string &path) {
    for (size_t k = 0; k < m.positions.size(); ++k)
        if (!is_finite(m.positions[k]))
            throw SceneError(path, "vertex " + std::to_string(k) + " has an invalid (NaN or infinite) position");
    for (size_t k = 0; k < m.normals.size(); ++k) {
        Vec3 &n = m.normals[k];
        if (!is_finite(n)) throw SceneError(path, "vertex " + std::to_string(k) + " has an invalid (NaN or infinite) normal");
        float len = norm(n);
        // Zero normals are kept: with face_normals=true Mitsuba never reads them, and the factory decides.
        if (len > 0) n = n / len;
    }
    for (size_t k = 0; k < m.uvs.size(); ++k)
        if (!std::isfinite(m.uvs[k].x) || !std::isfinite(m.uvs[k].y))
            throw SceneError(path, "vertex " + std::to_string(k) + " has an invalid (NaN or infinite) texture coordinate");
    for (uint32_t i : m.indices)
        if (i >= m.positions.size())
            throw SceneError(path, "face references vertex " + std::to_string(i) + " but there are only " +
                                       std::to_string(m.positions.size()));
}

}  // namespace mesh_detail
}  // namespace neepp
