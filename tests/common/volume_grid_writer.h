// Writes grids in Mitsuba's .vol layout (version 3, float32), for the reader's and the sdfgrid shape's
// tests and the fuzzer's seeds. Mitsuba's Python package writes the same bytes (mi.VolumeGrid.write).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace neepp::testing {

struct VolumeGridFile {
    int32_t size[3] = {2, 2, 2}, channels = 1;
    std::vector<float> values;  // x fastest, then y, then z, a point's channels together
    std::array<float, 6> bounds = {0, 0, 0, 1, 1, 1};
    uint8_t version = 3;
    int32_t data_type = 1;
};

inline std::string volume_grid_bytes(const VolumeGridFile &g) {
    std::string s = "VOL";
    s.push_back(char(g.version));
    auto put = [&](auto v) { s.append(reinterpret_cast<const char *>(&v), sizeof v); };
    put(g.data_type);
    for (int32_t n : g.size) put(n);
    put(g.channels);
    for (float b : g.bounds) put(b);
    for (float v : g.values) put(v);
    return s;
}

// A sphere's signed distance sampled on an n^3 grid over [0, 1]^3.
inline VolumeGridFile sphere_sdf_grid(int n, float cx = 0.5f, float cy = 0.5f, float cz = 0.5f, float radius = 0.3f) {
    VolumeGridFile g;
    g.size[0] = g.size[1] = g.size[2] = n;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const float dx = float(x) / float(n - 1) - cx, dy = float(y) / float(n - 1) - cy, dz = float(z) / float(n - 1) - cz;
                g.values.push_back(std::sqrt(dx * dx + dy * dy + dz * dz) - radius);
            }
    return g;
}

}  // namespace neepp::testing
