// Mitsuba's `.vol` grid files (its VolumeGrid: what `gridvolume` and `sdfgrid` read), read the way
// Mitsuba 3 reads them.
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include "neepp/math/bbox.h"

namespace neepp {

struct VolumeGrid {
    uint32_t size[3] = {0, 0, 0};  // x, y, z
    uint32_t channels = 0;
    BBox bounds;                    // as stored; `sdfgrid` ignores it (its grid spans [0, 1]^3)
    // size[0] * size[1] * size[2] * channels values, x fastest, then y, then z, a point's channels together.
    std::vector<float> values;
    // What Mitsuba reads without a word but is most likely a mistake (data beyond the values the header
    // gives: a wrong size or channel count), for the loader to warn about; empty when none.
    std::string warning;

    float at(uint32_t x, uint32_t y, uint32_t z, uint32_t channel = 0) const {
        return values[((size_t(z) * size[1] + y) * size[0] + x) * channels + channel];
    }
};

// Version 3 of the format, the one Mitsuba 3 reads and writes: little-endian, the bytes 'V' 'O' 'L' and the
// version, an int32 data type (1: float32, the only one Mitsuba 3 accepts), int32 sizes x, y, z and channel
// count, six floats of bounds (min, max), then the values. Bytes after the values are ignored, as
// Mitsuba does, and said in `warning`. Throws SceneError naming the path on a missing, truncated or
// malformed file.
VolumeGrid read_volume_grid(const std::string &path);

}  // namespace neepp
