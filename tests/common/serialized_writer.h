// Writes meshes in Mitsuba's .serialized layout (versions 3 and 4), every optional part included, for
// the reader's tests and the fuzzer's seeds (Mitsuba 3.9's Python package has no writer).
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>
#include <zlib.h>

namespace neepp::testing {

struct SerializedTestMesh {
    std::string name = "mesh";
    std::vector<float> positions, normals, uvs, colors;  // 3, 3, 2, 3 per vertex; empty when absent
    std::vector<uint32_t> indices;
    bool double_precision = false;
};

template <typename T> void put_le(std::string &s, T v) { s.append(reinterpret_cast<const char *>(&v), sizeof(T)); }

inline void put_reals(std::string &s, const std::vector<float> &v, bool dp) {
    for (float x : v) dp ? put_le(s, double(x)) : put_le(s, x);
}

inline std::string deflate(const std::string &raw) {
    uLongf size = compressBound(uLong(raw.size()));
    std::string out(size, '\0');
    if (compress(reinterpret_cast<Bytef *>(out.data()), &size, reinterpret_cast<const Bytef *>(raw.data()),
                 uLong(raw.size())) != Z_OK)
        throw std::runtime_error("zlib compress failed");
    out.resize(size);
    return out;
}

// A file in Mitsuba's layout: per mesh the header and its zlib stream, then the offset table.
inline std::string serialized(const std::vector<SerializedTestMesh> &meshes, uint16_t version = 4) {
    std::string file;
    std::vector<uint64_t> offsets;
    for (const SerializedTestMesh &m : meshes) {
        offsets.push_back(file.size());
        put_le(file, uint16_t(0x041C));
        put_le(file, version);
        std::string raw;
        const uint32_t flags = (m.normals.empty() ? 0 : 0x1) | (m.uvs.empty() ? 0 : 0x2) |
                               (m.colors.empty() ? 0 : 0x8) | (m.double_precision ? 0x2000 : 0x1000);
        put_le(raw, flags);
        if (version == 4) raw.append(m.name.c_str(), m.name.size() + 1);
        put_le(raw, uint64_t(m.positions.size() / 3));
        put_le(raw, uint64_t(m.indices.size() / 3));
        put_reals(raw, m.positions, m.double_precision);
        put_reals(raw, m.normals, m.double_precision);
        put_reals(raw, m.uvs, m.double_precision);
        put_reals(raw, m.colors, m.double_precision);
        for (uint32_t i : m.indices) put_le(raw, i);
        file += deflate(raw);
    }
    for (uint64_t o : offsets) version == 4 ? put_le(file, o) : put_le(file, uint32_t(o));
    put_le(file, uint32_t(meshes.size()));
    return file;
}

}  // namespace neepp::testing
