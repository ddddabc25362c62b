// The packets of tev's IPC protocol (the HDR viewer, github.com/Tom94/tev, src/Ipc.cpp) that a renderer
// sends to show an image as it converges: create an image, then replace rectangles of it. Encoding only,
// apart from the socket (tcp_connection.h), so that the bytes can be tested.
//
// A packet is little-endian: a uint32 length (of the whole packet, these four bytes included), a byte
// that says which packet it is, then its fields. A bool is one byte (0 or 1), a string its bytes and a
// NUL, int32 and int64 plain two's complement, floats IEEE 754 binary32.
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include "neepp/io/image.h"

namespace neepp::tev {

// The packet types neepp sends (tev's IpcPacket::EType).
enum class PacketType : uint8_t {
    CreateImage = 4,    // an empty image of a size and channels, replacing one of the same name
    UpdateImageV3 = 6,  // a rectangle of some channels, each at its own offset and stride in the data
};

// tev's channel names for an image's channels: Y, Y A, R G B or R G B A (alpha last, as Image keeps it).
std::vector<std::string> channel_names(int channels);

// CreateImage: the image `name`, width x height, with these channels, all zero. grab_focus makes tev
// show it.
std::vector<uint8_t> create_image_packet(const std::string &name, bool grab_focus, int width, int height,
                                         const std::vector<std::string> &channels);

// UpdateImage (version 3) of the rectangle x, y, w, h of `image`, all its channels: the rectangle's
// pixels go row by row with their channels interleaved, as Image holds them, so channel c is at offset c
// with stride image.channels. Throws std::invalid_argument for a rectangle outside the image or a packet
// too large for its uint32 length.
std::vector<uint8_t> update_image_packet(const std::string &name, bool grab_focus, const Image &image, int x, int y,
                                         int w, int h);

// The image cut into tiles of at most tile_size x tile_size pixels, row by row, one UpdateImage each: tev
// reads a packet whole into memory, so a large image goes in pieces of a few hundred kilobytes, and a
// sender may stop between two of them.
struct TileRect {
    int x, y, w, h;
    bool operator==(const TileRect &) const = default;
};
std::vector<TileRect> image_tiles(int width, int height, int tile_size);

}  // namespace neepp::tev
