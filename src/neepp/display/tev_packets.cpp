#include "neepp/display/tev_packets.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string_view>

namespace neepp::tev {
namespace {

// Appends fields in tev's byte order (little-endian, whatever this machine's), then writes the length
// in front when the packet is done.
class PacketWriter {
public:
    explicit PacketWriter(PacketType type, size_t expected_size = 64) {
        bytes_.reserve(expected_size);
        put_u32(0);  // the length, written by finish()
        bytes_.push_back(uint8_t(type));
    }
    void put_bool(bool v) { bytes_.push_back(v ? 1 : 0); }
    void put_string(std::string_view s) {
        // A NUL would end the string early on tev's side and shift every later field.
        if (s.find('\0') != std::string_view::npos) throw std::invalid_argument("tev: a name may not contain a NUL");
        bytes_.insert(bytes_.end(), s.begin(), s.end());
        bytes_.push_back(0);
    }
    void put_u32(uint32_t v) {
        for (int i = 0; i < 4; ++i) bytes_.push_back(uint8_t(v >> (8 * i)));
    }
    void put_i32(int32_t v) { put_u32(uint32_t(v)); }
    void put_i64(int64_t v) {
        for (int i = 0; i < 8; ++i) bytes_.push_back(uint8_t(uint64_t(v) >> (8 * i)));
    }
    void put_f32s(const float *v, size_t n) {
        if constexpr (std::endian::native == std::endian::little) {  // as they are: the pixels are most of the bytes
            const size_t at = bytes_.size();
            bytes_.resize(at + 4 * n);
            std::memcpy(bytes_.data() + at, v, 4 * n);
        } else {
            for (size_t i = 0; i < n; ++i) {
                uint32_t bits;
                std::memcpy(&bits, &v[i], 4);
                put_u32(bits);
            }
        }
    }
    std::vector<uint8_t> finish() {
        if (bytes_.size() > std::numeric_limits<uint32_t>::max())
            throw std::invalid_argument("tev: a packet may not exceed 4 GiB (send the image in tiles)");
        const uint32_t n = uint32_t(bytes_.size());
        for (int i = 0; i < 4; ++i) bytes_[i] = uint8_t(n >> (8 * i));
        return std::move(bytes_);
    }

private:
    std::vector<uint8_t> bytes_;
};

}  // namespace

std::vector<std::string> channel_names(int channels) {
    std::vector<std::string> names = neepp::channel_names(channels);  // the EXR's, so tev shows what is written
    if (names.empty()) throw std::invalid_argument("tev: an image has 1 to 4 channels, not " + std::to_string(channels));
    return names;
}

std::vector<uint8_t> create_image_packet(const std::string &name, bool grab_focus, int width, int height,
                                         const std::vector<std::string> &channels) {
    if (width <= 0 || height <= 0) throw std::invalid_argument("tev: an image needs a positive size");
    if (channels.empty()) throw std::invalid_argument("tev: an image needs a channel");
    PacketWriter p(PacketType::CreateImage);
    p.put_bool(grab_focus);
    p.put_string(name);
    p.put_i32(width);
    p.put_i32(height);
    p.put_i32(int32_t(channels.size()));
    for (const std::string &c : channels) p.put_string(c);
    return p.finish();
}

std::vector<uint8_t> update_image_packet(const std::string &name, bool grab_focus, const Image &image, int x, int y,
                                         int w, int h) {
    if (x < 0 || y < 0 || w <= 0 || h <= 0 || x + w > image.width || y + h > image.height)
        throw std::invalid_argument("tev: the rectangle to update is not inside the image");
    const std::vector<std::string> names = channel_names(image.channels);
    const int n = image.channels;
    const size_t floats = size_t(w) * h * n;
    // Checked before anything is written: the data alone may be too large for the length field.
    if (floats > (std::numeric_limits<uint32_t>::max() - 4096 - name.size()) / 4)
        throw std::invalid_argument("tev: a packet may not exceed 4 GiB (send the image in tiles)");
    PacketWriter p(PacketType::UpdateImageV3, 64 + name.size() + 4 * floats);
    p.put_bool(grab_focus);
    p.put_string(name);
    p.put_i32(n);
    for (const std::string &c : names) p.put_string(c);
    p.put_i32(x);
    p.put_i32(y);
    p.put_i32(w);
    p.put_i32(h);
    for (int c = 0; c < n; ++c) p.put_i64(c);  // offsets
    for (int c = 0; c < n; ++c) p.put_i64(n);  // strides
    for (int row = y; row < y + h; ++row) {
        const float *v = &image.data[(size_t(row) * image.width + x) * n];
        p.put_f32s(v, size_t(w) * n);
    }
    return p.finish();
}

std::vector<TileRect> image_tiles(int width, int height, int tile_size) {
    if (tile_size <= 0) throw std::invalid_argument("tev: tiles need a positive size");
    std::vector<TileRect> tiles;
    for (int y = 0; y < height; y += tile_size)
        for (int x = 0; x < width; x += tile_size)
            tiles.push_back({x, y, std::min(tile_size, width - x), std::min(tile_size, height - y)});
    return tiles;
}

}  // namespace neepp::tev
