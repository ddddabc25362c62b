// tev's IPC packets, byte for byte against what tev's reader (src/Ipc.cpp, IpcPacket::interpretAs*) expects:
// a uint32 length of the whole packet, the type, then the fields, little-endian.
#include <gtest/gtest.h>
#include <cstring>
#include "neepp/display/tev_packets.h"

using namespace neepp;

namespace {

std::vector<uint8_t> bytes(std::initializer_list<int> values) {
    std::vector<uint8_t> out;
    for (int v : values) out.push_back(uint8_t(v));
    return out;
}

float float_at(const std::vector<uint8_t> &p, size_t at) {
    float f;
    std::memcpy(&f, &p[at], 4);  // the tests run little-endian, as tev's wire format is
    return f;
}

}  // namespace

TEST(TevPackets, CreateImageBytes) {
    const std::vector<uint8_t> p = tev::create_image_packet("a", true, 2, 1, {"R", "G", "B"});
    EXPECT_EQ(p, bytes({26, 0, 0, 0,      // length: the whole packet
                        4,                // CreateImage
                        1,                // grab focus
                        'a', 0,           // name
                        2, 0, 0, 0,       // width
                        1, 0, 0, 0,       // height
                        3, 0, 0, 0,       // channels
                        'R', 0, 'G', 0, 'B', 0}));
}

TEST(TevPackets, UpdateImageBytesOfOnePixel) {
    Image image(2, 1, 3);
    image.data = {1.f, 2.f, -0.5f, 0.25f, 0.f, 3.f};
    const std::vector<uint8_t> p = tev::update_image_packet("a", false, image, 1, 0, 1, 1);
    EXPECT_EQ(p, bytes({94, 0, 0, 0,                    // length
                        6,                              // UpdateImageV3
                        0,                              // no focus
                        'a', 0,                         // name
                        3, 0, 0, 0,                     // channels
                        'R', 0, 'G', 0, 'B', 0,         //
                        1, 0, 0, 0, 0, 0, 0, 0,         // x, y
                        1, 0, 0, 0, 1, 0, 0, 0,         // width, height
                        0, 0, 0, 0, 0, 0, 0, 0,         // offsets (int64): R at 0,
                        1, 0, 0, 0, 0, 0, 0, 0,         //   G at 1,
                        2, 0, 0, 0, 0, 0, 0, 0,         //   B at 2
                        3, 0, 0, 0, 0, 0, 0, 0,         // strides (int64): 3, 3, 3
                        3, 0, 0, 0, 0, 0, 0, 0,         //
                        3, 0, 0, 0, 0, 0, 0, 0,         //
                        0x00, 0x00, 0x80, 0x3e,         // 0.25 (0x3e800000)
                        0x00, 0x00, 0x00, 0x00,         // 0
                        0x00, 0x00, 0x40, 0x40}));      // 3 (0x40400000)
}

TEST(TevPackets, UpdateImageSendsTheRectangleRowByRow) {
    // A 3 x 2 RGBA image; the rectangle x 1..2, y 0..1: pixels (1,0) (2,0) (1,1) (2,1), channels interleaved.
    Image image(3, 2, 4);
    for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = float(i);
    const std::vector<uint8_t> p = tev::update_image_packet("img", false, image, 1, 0, 2, 2);
    const size_t header = 4 + 1 + 1 + 4 + 4 + 8 + 16 + 4 * 8 + 4 * 8;  // ... "img\0", "R\0G\0B\0A\0"
    ASSERT_EQ(p.size(), header + 2 * 2 * 4 * 4);
    EXPECT_EQ(p[header - 64 - 16 - 2], 'A');  // the last channel name, before x, y, w, h: alpha
    for (int c = 0; c < 4; ++c) {
        EXPECT_EQ(p[header - 64 + 8 * c], c);        // offset c
        EXPECT_EQ(p[header - 32 + 8 * c], 4);        // stride 4
    }
    const int pixels[4][2] = {{1, 0}, {2, 0}, {1, 1}, {2, 1}};
    for (int k = 0; k < 4; ++k)
        for (int c = 0; c < 4; ++c)
            EXPECT_EQ(float_at(p, header + 4 * (4 * k + c)), image.at(pixels[k][0], pixels[k][1], c)) << k << " " << c;
}

TEST(TevPackets, ChannelNames) {
    EXPECT_EQ(tev::channel_names(1), (std::vector<std::string>{"Y"}));
    EXPECT_EQ(tev::channel_names(3), (std::vector<std::string>{"R", "G", "B"}));
    EXPECT_EQ(tev::channel_names(4), (std::vector<std::string>{"R", "G", "B", "A"}));
    EXPECT_THROW(tev::channel_names(5), std::invalid_argument);
}

TEST(TevPackets, TilesCoverTheImageOnce) {
    const std::vector<tev::TileRect> tiles = tev::image_tiles(300, 130, 128);
    const std::vector<tev::TileRect> expected = {{0, 0, 128, 128},   {128, 0, 128, 128},   {256, 0, 44, 128},
                                                 {0, 128, 128, 2},   {128, 128, 128, 2},   {256, 128, 44, 2}};
    EXPECT_EQ(tiles, expected);
    EXPECT_EQ(tev::image_tiles(5, 5, 128).size(), 1u);
}

TEST(TevPackets, BadRequestsAreRefused) {
    Image image(2, 2, 3);
    EXPECT_THROW(tev::update_image_packet("a", false, image, 1, 0, 2, 1), std::invalid_argument);  // past the edge
    EXPECT_THROW(tev::update_image_packet("a", false, image, 0, 0, 0, 1), std::invalid_argument);  // empty
    EXPECT_THROW(tev::create_image_packet(std::string("a\0b", 3), true, 2, 2, {"R"}), std::invalid_argument);
    EXPECT_THROW(tev::create_image_packet("a", true, 0, 2, {"R"}), std::invalid_argument);
    EXPECT_THROW(tev::image_tiles(4, 4, 0), std::invalid_argument);
}
