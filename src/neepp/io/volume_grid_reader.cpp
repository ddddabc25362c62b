// Layout from Mitsuba 3's src/render/volumegrid.cpp (VolumeGrid::read) and the `gridvolume` plugin's
// description of the format.
#include "neepp/io/volume_grid_reader.h"

#include <bit>
#include <cstring>
#include "neepp/io/binary_io.h"
#include "neepp/io/scene_error.h"

namespace neepp {

namespace {

static_assert(std::endian::native == std::endian::little, "the .vol reader assumes a little-endian host");

constexpr size_t kHeaderBytes = 3 + 1 + 4 * 5 + 4 * 6;

// "4 x 4 x 2 points of 3 channels", what the header says the data is.
std::string shape_text(const int32_t dims[4]) {
    return std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " + std::to_string(dims[2]) + " points of " +
           std::to_string(dims[3]) + (dims[3] == 1 ? " channel" : " channels");
}

}  // namespace

VolumeGrid read_volume_grid(const std::string &path) {
    std::string data;
    try {
        data = read_file_bytes(path, "volume grid");
    } catch (const std::exception &) {
        throw SceneError(path, "cannot open the volume grid file");
    }
    if (data.size() < 4 || data.compare(0, 3, "VOL") != 0)
        throw SceneError(path, "not a Mitsuba volume grid (.vol) file: it does not start with 'VOL'");
    if (const int version = uint8_t(data[3]); version != 3)
        throw SceneError(path, "volume grid file version " + std::to_string(version) + " (only version 3 is supported)");
    if (data.size() < kHeaderBytes) throw SceneError(path, "truncated volume grid file (the header ends early)");
    if (const int32_t type = load_at<int32_t>(data, 4); type != 1)
        throw SceneError(path, "volume grid data type " + std::to_string(type) +
                                   " (only type 1, float32, is supported, as in Mitsuba 3)");
    VolumeGrid g;
    const int32_t dims[4] = {load_at<int32_t>(data, 8), load_at<int32_t>(data, 12), load_at<int32_t>(data, 16),
                             load_at<int32_t>(data, 20)};
    if (dims[0] < 1 || dims[1] < 1 || dims[2] < 1)
        throw SceneError(path, "volume grid size " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
                                   std::to_string(dims[2]) + " is invalid (each must be at least 1)");
    if (dims[3] < 1) throw SceneError(path, "volume grid with " + std::to_string(dims[3]) + " channels (at least 1 is needed)");
    for (int i = 0; i < 3; ++i) g.size[i] = uint32_t(dims[i]);
    g.channels = uint32_t(dims[3]);
    float b[6];
    std::memcpy(b, data.data() + 24, sizeof b);
    g.bounds.lo = {b[0], b[1], b[2]};
    g.bounds.hi = {b[3], b[4], b[5]};
    // Each factor is below 2^31, so the product of the four fits 128 bits but not always 64: checked as
    // the file's own size allows, before anything is allocated.
    const size_t available = (data.size() - kHeaderBytes) / sizeof(float);
    size_t count = 1;
    for (int32_t d : dims) {
        if (size_t(d) > available / count)
            throw SceneError(path, "truncated volume grid file: the header gives " + shape_text(dims) +
                                       ", more values than the file's " + std::to_string(data.size() - kHeaderBytes) +
                                       " bytes of data hold");
        count *= size_t(d);
    }
    g.values.resize(count);
    std::memcpy(g.values.data(), data.data() + kHeaderBytes, count * sizeof(float));
    if (const size_t extra = data.size() - kHeaderBytes - count * sizeof(float); extra > 0) {
        const size_t whole = data.size() - kHeaderBytes;
        g.warning = std::to_string(extra) + " bytes after the " + shape_text(dims) +
                    " that the header gives are ignored, as Mitsuba ignores them";
        // The commonest mistake: a channel count or a size that divides the data's true shape.
        if (whole % (count * sizeof(float)) == 0)
            g.warning += "; the file holds exactly " + std::to_string(whole / (count * sizeof(float))) +
                         " times as many values: is the size or the channel count wrong?";
    }
    return g;
}

}  // namespace neepp
