#include <ImfBoxAttribute.h>
#include <ImfChannelList.h>
#include <ImfChromaticitiesAttribute.h>
#include <ImfDeepImageStateAttribute.h>
#include <ImfDoubleAttribute.h>
#include <ImfEnvmapAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfKeyCodeAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>
#include <ImfPreviewImageAttribute.h>
#include <ImfRationalAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <ImfTileDescriptionAttribute.h>
#include <ImfTiledOutputFile.h>
#include <ImfTimeCodeAttribute.h>
#include <ImfVecAttribute.h>
#include <gtest/gtest.h>
#include <jpeglib.h>
#include <stb/stb_image_write.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <cstring>
#include <iterator>
#include <sys/resource.h>
#include <filesystem>
#include <functional>
#include <vector>
#include <fstream>
#include <stdexcept>
#include <string>

#include "neepp/io/image.h"

using namespace neepp;

namespace {

std::string temp_path(const std::string &name) {
    return (std::filesystem::temp_directory_path() / ("neepp_test_image_" + name)).string();
}

Image ramp(int w, int h, int c) {
    Image img(w, h, c);
    for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = 0.37f * float(i) - 1.5f;
    return img;
}

// Expects fn to throw std::runtime_error whose message names path.
template <typename Fn>
void expect_error_naming(const std::string &path, Fn fn) {
    try {
        fn();
        FAIL() << "no exception for " << path;
    } catch (const std::runtime_error &e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

}  // namespace

TEST(Image, ExrFloatRoundTripIsExact) {
    for (int c : {1, 3, 4}) {
        Image img = ramp(5, 3, c);
        std::string path = temp_path("float.exr");
        write_exr(path, img, false);
        Image back = read_image(path);
        EXPECT_EQ(back.width, 5);
        EXPECT_EQ(back.height, 3);
        EXPECT_EQ(back.channels, c);
        EXPECT_FALSE(back.srgb_encoded);
        EXPECT_EQ(back.data, img.data);
        std::filesystem::remove(path);
    }
}

TEST(Image, ExrHalfRoundTripWithinHalfPrecision) {
    Image img = ramp(4, 4, 3);
    std::string path = temp_path("half.exr");
    write_exr(path, img, true);
    Image back = read_image(path);
    ASSERT_EQ(back.data.size(), img.data.size());
    for (size_t i = 0; i < img.data.size(); ++i)
        EXPECT_NEAR(back.data[i], img.data[i], std::abs(img.data[i]) * 1e-3f + 1e-6f);
    std::filesystem::remove(path);
}

TEST(Image, PngWriteThenReadIsSrgbEncoded) {
    Image img(3, 2, 3);
    const float values[] = {0.f, 0.001f, 0.0031308f, 0.05f, 0.2f, 0.5f, 0.8f, 1.f, 2.f};
    for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = values[i % 9];
    img.at(2, 1, 0) = -1.f;  // clamped to 0
    std::string path = temp_path("srgb.png");
    write_png_srgb(path, img, 1.f);
    Image back = read_image(path);
    ASSERT_EQ(back.width, 3);
    ASSERT_EQ(back.height, 2);
    ASSERT_EQ(back.channels, 3);
    EXPECT_TRUE(back.srgb_encoded);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x)
            for (int c = 0; c < 3; ++c) {
                float expected = std::round(linear_to_srgb(std::clamp(img.at(x, y, c), 0.f, 1.f)) * 255.f);
                EXPECT_FLOAT_EQ(back.at(x, y, c) * 255.f, expected) << x << "," << y << "," << c;
            }
    std::filesystem::remove(path);
}

TEST(Image, PngExposureScalesBeforeEncoding) {
    Image img(1, 1, 3);
    img.data = {0.25f, 0.5f, 1.f};
    std::string path = temp_path("exposure.png");
    write_png_srgb(path, img, 2.f);
    Image back = read_image(path);
    EXPECT_FLOAT_EQ(back.data[0] * 255.f, std::round(linear_to_srgb(0.5f) * 255.f));
    EXPECT_FLOAT_EQ(back.data[1], 1.f);
    EXPECT_FLOAT_EQ(back.data[2], 1.f);
    std::filesystem::remove(path);
}

TEST(Image, GrayAlphaPngKeepsAlphaLinear) {
    Image img(2, 1, 2);
    img.data = {0.2f, 0.4f, 1.f, 1.f};
    std::string path = temp_path("ya.png");
    write_png_srgb(path, img);
    Image back = read_image(path);
    ASSERT_EQ(back.channels, 2);
    EXPECT_TRUE(back.has_alpha());
    EXPECT_EQ(back.color_channels(), 1);
    EXPECT_FLOAT_EQ(back.data[1] * 255.f, std::round(0.4f * 255.f));
    EXPECT_FLOAT_EQ(back.data[0] * 255.f, std::round(linear_to_srgb(0.2f) * 255.f));
    std::filesystem::remove(path);
}

TEST(Image, MissingFileNamesPath) {
    std::string path = temp_path("does_not_exist.exr");
    expect_error_naming(path, [&] { read_image(path); });
}

TEST(Image, CorruptFilesNamePath) {
    std::string png = temp_path("corrupt.png");
    std::ofstream(png, std::ios::binary) << "this is not an image";
    expect_error_naming(png, [&] { read_image(png); });
    std::filesystem::remove(png);

    // A valid EXR magic number followed by garbage must fail inside OpenEXR, not crash.
    std::string exr = temp_path("corrupt.exr");
    std::ofstream(exr, std::ios::binary) << "\x76\x2f\x31\x01 garbage garbage garbage";
    expect_error_naming(exr, [&] { read_image(exr); });
    std::filesystem::remove(exr);

    std::string jpg = temp_path("corrupt.jpg");  // JPEG start-of-image marker, then garbage
    std::ofstream(jpg, std::ios::binary) << "\xff\xd8\xff\xe0 garbage";
    expect_error_naming(jpg, [&] { read_image(jpg); });
    std::filesystem::remove(jpg);
}

TEST(Image, WriteToUnwritablePathNamesPath) {
    std::string path = "/nonexistent_dir_neepp/out.exr";
    expect_error_naming(path, [&] { write_exr(path, ramp(2, 2, 3)); });
    expect_error_naming("/nonexistent_dir_neepp/out.png", [&] {
        write_png_srgb("/nonexistent_dir_neepp/out.png", ramp(2, 2, 3));
    });
}

TEST(Image, SrgbTransferFunctionsArePiecewiseAndInverse) {
    EXPECT_FLOAT_EQ(srgb_to_linear(0.04045f), 0.04045f / 12.92f);
    EXPECT_NEAR(srgb_to_linear(0.5f), 0.21404114f, 1e-7f);
    EXPECT_FLOAT_EQ(srgb_to_linear(1.f), 1.f);
    EXPECT_FLOAT_EQ(linear_to_srgb(0.002f), 0.002f * 12.92f);
    EXPECT_NEAR(linear_to_srgb(0.21404114f), 0.5f, 1e-6f);
    for (int i = 0; i <= 255; ++i) {
        float v = i / 255.f;
        EXPECT_NEAR(linear_to_srgb(srgb_to_linear(v)), v, 2e-6f);
    }
}

namespace {

// The file's bytes with its dataWindow attribute (a box2i: xmin, ymin, xmax, ymax) set to the window given.
std::string with_data_window(std::string bytes, int32_t xmin, int32_t ymin, int32_t xmax, int32_t ymax) {
    const std::string attribute("dataWindow\0box2i\0", 17);
    const size_t at = bytes.find(attribute);
    if (at == std::string::npos) throw std::logic_error("no dataWindow in the EXR header");
    const int32_t box[4] = {xmin, ymin, xmax, ymax};
    std::memcpy(&bytes[at + attribute.size() + 4], box, sizeof box);  // after the attribute's size (16)
    return bytes;
}

std::string read_bytes(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

// A damaged header may ask for any data window: beyond the film's cap it is refused from the header, and a
// window within it that the file's data does not cover is refused before its pixels are allocated (a
// 30000² RGB window is 10 GB of floats; the fuzzer met such headers at every other input).
TEST(Image, ExrDataWindowIsCappedBeforeThePixelsAreRead) {
    const std::string path = temp_path("window.exr");
    write_exr(path, ramp(4, 3, 3));
    const std::string good = read_bytes(path);
    EXPECT_EQ(read_image(path).width, 4);
    auto message = [&](const std::string &bytes) {
        std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
        try {
            read_image(path);
        } catch (const std::runtime_error &e) {
            return std::string(e.what());
        }
        return std::string("(read)");
    };
    for (auto [w, h] : {std::pair{40000, 3}, std::pair{4, 40000}, std::pair{2000000000, 2000000000}}) {
        const std::string msg = message(with_data_window(good, 0, 0, w - 1, h - 1));
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find("data window"), std::string::npos) << w << "x" << h << ": " << msg;
        if (w < 100000) EXPECT_NE(msg.find("32768"), std::string::npos) << w << "x" << h << ": " << msg;
    }
    // Within the cap, a window the file's data does not cover: refused before its 10 GB of pixels are
    // allocated (the process would grow by them, or be killed).
    rusage before{}, after{};
    getrusage(RUSAGE_SELF, &before);
    const std::string msg = message(with_data_window(good, 0, 0, 29999, 29999));
    getrusage(RUSAGE_SELF, &after);
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("(read)"), 0u) << msg;
    EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 256 * 1024) << "kB grown: " << after.ru_maxrss - before.ru_maxrss;
    EXPECT_EQ(message(good), "(read)");
    std::filesystem::remove(path);
}

// The largest operator new[] of this test program while counting is on: OpenEXR allocates a header
// attribute's value with new char[size], so the test below can see whether a claimed size was allocated.
namespace {
std::atomic<bool> counting_new{false};
std::atomic<size_t> largest_new{0};
}  // namespace

void *operator new[](std::size_t n) {
    if (counting_new.load(std::memory_order_relaxed) && n > largest_new.load(std::memory_order_relaxed))
        largest_new.store(n, std::memory_order_relaxed);
    if (void *p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
// The nothrow form too, so that every delete[] (replaced below) frees what malloc gave (AddressSanitizer
// reports a mismatch otherwise: libstdc++'s ios_base allocates with new[](n, nothrow)).
void *operator new[](std::size_t n, const std::nothrow_t &) noexcept { return std::malloc(n ? n : 1); }
void operator delete[](void *p) noexcept { std::free(p); }
void operator delete[](void *p, std::size_t) noexcept { std::free(p); }
void operator delete[](void *p, const std::nothrow_t &) noexcept { std::free(p); }

namespace {

// A one-chunk OpenEXR file's bytes with an attribute (name, type name, claimed size, then the bytes given)
// added at the start of its header, right after the magic number and version, and its chunk offset table
// (one offset, pointing right behind itself) moved along.
std::string with_attribute(const std::string &bytes, const std::string &name, const std::string &type, int32_t size,
                           const std::string &value) {
    std::string attribute = name + '\0' + type + '\0';
    attribute.append(reinterpret_cast<const char *>(&size), 4);  // little-endian, as the file is
    attribute += value;
    std::string out = bytes.substr(0, 8) + attribute + bytes.substr(8);
    for (size_t at = 8; at + 8 <= bytes.size(); ++at) {
        uint64_t offset;
        std::memcpy(&offset, &bytes[at], 8);
        if (offset != at + 8) continue;
        offset += attribute.size();
        std::memcpy(&out[at + attribute.size()], &offset, 8);
        return out;
    }
    throw std::logic_error("no chunk offset table in the EXR file");
}

}  // namespace

// OpenEXR allocates an attribute's value at the size its header claims before reading it (an unknown
// type's as new char[size], up to 2 GB; a string's zero-filled): an attribute claiming more
// than the file holds is refused from the header, naming the file, the attribute and the size, before
// OpenEXR allocates it (the fuzzer met such headers at 78 % of its time).
TEST(Image, ExrAttributeSizesAreCheckedBeforeOpenExrAllocatesThem) {
    const std::string path = temp_path("attribute.exr");
    write_exr(path, ramp(4, 3, 3));
    const std::string good = read_bytes(path);
    auto message = [&](const std::string &bytes) {
        std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
        largest_new = 0;
        counting_new = true;
        std::string msg = "(read)";
        try {
            read_image(path);
        } catch (const std::exception &e) {
            msg = e.what();
        }
        counting_new = false;
        return msg;
    };
    // A small attribute of an unknown type that the file does hold is read (OpenEXR keeps it opaque).
    EXPECT_EQ(message(with_attribute(good, "note", "neeppnote", 5, "hello")), "(read)");
    for (int32_t size : {2000000000, -7, 4096}) {
        const std::string msg = message(with_attribute(good, "note", "neeppnote", size, "hello"));
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find("'note'"), std::string::npos) << msg;
        EXPECT_NE(msg.find(std::to_string(size) + " bytes"), std::string::npos) << msg;
        EXPECT_LT(largest_new.load(), size_t(1) << 20) << size << ": " << msg;
    }
    // A known type's attribute (a string) claiming more than the file holds.
    std::string msg = message(with_attribute(good, "owner", "string", 100000000, "me"));
    EXPECT_NE(msg.find("'owner'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("100000000 bytes"), std::string::npos) << msg;
    // OpenEXR reads a channel list up to its empty name and an int as 4 bytes, whatever their size fields
    // say: the attribute after such a one is where OpenEXR reads it, and is checked there.
    const std::string huge = with_attribute(good, "note", "neeppnote", 2000000000, "hello");
    const std::string channel = std::string("Q\0", 2) + std::string(16, '\1') + '\0';
    for (const std::string &bytes : {with_attribute(huge, "pad", "int", 1000000, "abcd"),
                                     with_attribute(huge, "more", "chlist", 3, channel)}) {
        msg = message(bytes);
        EXPECT_NE(msg.find("'note'"), std::string::npos) << msg;
        EXPECT_LT(largest_new.load(), size_t(1) << 20) << msg;
    }
    EXPECT_EQ(message(with_attribute(good, "pad", "int", 1000000, "abcd")), "(read)");
    EXPECT_EQ(message(good), "(read)");
    std::filesystem::remove(path);
}

// stb_image grows its buffer for a PNG's IDAT data to the size each chunk claims (up to 2 GB) before it
// reads the chunk: a chunk claiming more than the file holds is refused first, naming the file, the chunk
// and the size.
TEST(Image, PngChunkLengthsAreCheckedBeforeTheyAreRead) {
    const std::string path = temp_path("chunk.png");
    write_png_srgb(path, ramp(4, 3, 3));
    const std::string good = read_bytes(path);
    const size_t idat = good.find("IDAT");
    ASSERT_NE(idat, std::string::npos);
    auto message = [&](const std::string &bytes) {
        std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
        try {
            read_image(path);
        } catch (const std::exception &e) {
            return std::string(e.what());
        }
        return std::string("(read)");
    };
    EXPECT_EQ(message(good), "(read)");
    for (uint32_t length : {0x7fff0000u, 0xfffffff0u, 5000u}) {
        std::string bad = good;
        for (int i = 0; i < 4; ++i) bad[idat - 4 + i] = char(length >> (24 - 8 * i));  // big-endian
        const std::string msg = message(bad);
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find("chunk 'IDAT' claims " + std::to_string(length) + " bytes"), std::string::npos) << msg;
        bool bytes_msg = false;
        try {
            read_image_bytes(path);
        } catch (const std::exception &e) {
            bytes_msg = std::string(e.what()).find("'IDAT'") != std::string::npos;
        }
        EXPECT_TRUE(bytes_msg) << length;
    }
    std::filesystem::remove(path);
}

// The header walk that checks attribute sizes steps over each known type at the size OpenEXR reads: a
// file with an attribute of every type OpenEXR 3.1 knows (and several of the sized ones) reads, as
// scan lines and as mipmapped tiles, so a wrong size in the walk's table would show as a refused file.
TEST(Image, ExrWithAttributesOfEveryTypeReads) {
    const Image img = ramp(5, 3, 3);
    Imf::Header header(img.width, img.height);
    header.insert("b2f", Imf::Box2fAttribute(Imath::Box2f(Imath::V2f(0.f, 1.f), Imath::V2f(2.f, 3.f))));
    header.insert("chroma", Imf::ChromaticitiesAttribute(Imf::Chromaticities()));
    header.insert("deep", Imf::DeepImageStateAttribute(Imf::DIS_TIDY));
    header.insert("dbl", Imf::DoubleAttribute(2.5));
    header.insert("env", Imf::EnvmapAttribute(Imf::ENVMAP_LATLONG));
    header.insert("flt", Imf::FloatAttribute(1.5f));
    header.insert("fv", Imf::FloatVectorAttribute(Imf::FloatVector{1.f, 2.f, 3.f}));
    header.insert("num", Imf::IntAttribute(7));
    header.insert("key", Imf::KeyCodeAttribute(Imf::KeyCode(1, 2, 3, 4, 5, 4, 64)));
    header.insert("m33d", Imf::M33dAttribute(Imath::M33d()));
    header.insert("m33f", Imf::M33fAttribute(Imath::M33f()));
    header.insert("m44d", Imf::M44dAttribute(Imath::M44d()));
    header.insert("m44f", Imf::M44fAttribute(Imath::M44f()));
    header.insert("preview", Imf::PreviewImageAttribute(Imf::PreviewImage(3, 2)));
    header.insert("rat", Imf::RationalAttribute(Imf::Rational(24000, 1001)));
    header.insert("owner", Imf::StringAttribute("neepp"));
    header.insert("sv", Imf::StringVectorAttribute(Imf::StringVector{"a", "", "bcd"}));
    header.insert("td", Imf::TileDescriptionAttribute(Imf::TileDescription(8, 8, Imf::MIPMAP_LEVELS)));
    header.insert("tc", Imf::TimeCodeAttribute(Imf::TimeCode(1, 2, 3, 4)));
    header.insert("v2d", Imf::V2dAttribute(Imath::V2d(1., 2.)));
    header.insert("v2f", Imf::V2fAttribute(Imath::V2f(1.f, 2.f)));
    header.insert("v2i", Imf::V2iAttribute(Imath::V2i(1, 2)));
    header.insert("v3d", Imf::V3dAttribute(Imath::V3d(1., 2., 3.)));
    header.insert("v3f", Imf::V3fAttribute(Imath::V3f(1.f, 2.f, 3.f)));
    header.insert("v3i", Imf::V3iAttribute(Imath::V3i(1, 2, 3)));
    const char *names[] = {"R", "G", "B"};
    for (const char *n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
    const size_t xstride = sizeof(float) * 3, ystride = xstride * img.width;
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char *)(img.data.data() + c), xstride, ystride));
    const std::string scanlines = temp_path("attributes.exr"), tiles = temp_path("attributes_tiled.exr");
    {
        Imf::OutputFile file(scanlines.c_str(), header);
        file.setFrameBuffer(fb);
        file.writePixels(img.height);
    }
    {
        Imf::Header tiled = header;
        tiled.setTileDescription(Imf::TileDescription(2, 2, Imf::MIPMAP_LEVELS));
        Imf::TiledOutputFile file(tiles.c_str(), tiled);
        file.setFrameBuffer(fb);
        for (int level = 0; level < file.numLevels(); ++level)  // each level's pixels: level 0's corner
            file.writeTiles(0, file.numXTiles(level) - 1, 0, file.numYTiles(level) - 1, level);
    }
    for (const std::string &path : {scanlines, tiles}) {
        Image back;
        try {
            back = read_image(path);
        } catch (const std::exception &e) {
            FAIL() << e.what();
        }
        EXPECT_EQ(back.width, img.width);
        EXPECT_EQ(back.data, img.data) << path;
        std::filesystem::remove(path);
    }
}

// A regression input of fuzz_image (build-sanitize/fuzz/artifacts/image/oom-e9d85ae8...): 199 bytes of
// baseline JPEG whose frame header asks for 16725x21334 RGB pixels. libjpeg decodes what is missing as
// gray with a warning, so reading it took 1 GB of codes and 4 GB of floats (over the fuzzer's 2 GB);
// it is refused from its header, naming the file and the size asked.
TEST(Image, JpegAskingForMoreBlocksThanItsBytesCanHoldIsRefused) {
    const std::string hex =
        "ffd8ffe000104a46464900010100000132010080ffdb00840009060614121114140f140000000000000000000f0f0f0f"
        "0f0f14151518151414ecebe8e3d9e1e8f0231914141f2f202327292c2c00007ffdc2361435262b2c2901090a0a0d0c0e"
        "172901090a0a0d0c0e170f0f142c1c1c1c2a2c2929292929292929292c2c2929292929292c29292c2c292929292c2929"
        "296a2c2c2c2c29292c2cffc0001108535641550301220002110103110100009b0001a1f012ffda000c03010002110311"
        "003f00ec4e8c32";
    std::string bytes;
    for (size_t i = 0; i + 1 < hex.size(); i += 2) bytes += char(std::stoi(hex.substr(i, 2), nullptr, 16));
    ASSERT_EQ(bytes.size(), 199u);
    const std::string path = temp_path("huge.jpg");
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    rusage before{}, after{};
    getrusage(RUSAGE_SELF, &before);
    for (int bytes_path = 0; bytes_path < 2; ++bytes_path) {
        std::string msg = "(read)";
        try {
            if (bytes_path) read_image_bytes(path);
            else read_image(path);
        } catch (const std::exception &e) {
            msg = e.what();
        }
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find("16725x21334"), std::string::npos) << msg;
    }
    getrusage(RUSAGE_SELF, &after);
    EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 256 * 1024) << "kB grown: " << after.ru_maxrss - before.ru_maxrss;
    std::filesystem::remove(path);
}

namespace {

// What reading the file gives: "(read)", or the error's message. Both entry points are run: read_image, and
// read_image_bytes, which may answer std::nullopt (a float format) but never an image the other refuses.
std::string read_message(const std::string &path) {
    std::string msg = "(read)";
    try {
        read_image(path);
    } catch (const std::exception &e) {
        msg = e.what();
    }
    try {
        read_image_bytes(path);
        if (msg != "(read)") return msg + " [but read_image_bytes read it]";
    } catch (const std::exception &e) {
        if (msg == "(read)") return std::string("(read) [but read_image_bytes: ") + e.what() + "]";
    }
    return msg;
}

std::string write_and_read_message(const std::string &path, const std::string &bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    return read_message(path);
}

// 8-bit pixels with both runs (a flat band) and noise, so that run-length coding leaves data to cut.
std::vector<unsigned char> test_pixels(int w, int h, int c) {
    std::vector<unsigned char> px(size_t(w) * h * c);
    for (size_t i = 0; i < px.size(); ++i) px[i] = (i / c) % w < size_t(w) / 3 ? 200 : (unsigned char)(i * 37 % 251);
    return px;
}

// The file cut at several points, from nothing to all but its last byte: every one is refused, naming the
// file.
void expect_every_cut_refused(const std::string &path, const std::string &good) {
    const size_t n = good.size();
    for (size_t cut : {size_t(0), size_t(1), size_t(2), size_t(5), size_t(11), size_t(17), size_t(30), size_t(60),
                       n / 4, n / 2, 3 * n / 4, n - n / 8, n - 13, n - 1}) {
        if (cut >= n) continue;
        const std::string msg = write_and_read_message(path, good.substr(0, cut));
        EXPECT_NE(msg.find(path), std::string::npos) << "cut at " << cut << " of " << n << ": " << msg;
        EXPECT_EQ(msg.find("(read)"), std::string::npos) << "cut at " << cut << " of " << n << ": " << msg;
    }
}

}  // namespace

// stb_image reads past the end of a file as zeros: each format it decodes for neepp is checked so that a
// truncated file is refused, by its header's size where the pixels are stored plainly (BMP, TGA, PNM, flat
// HDR) and by seeing stb_image read past the end where they are run-length coded (TGA, HDR) or deflated (PNG).
TEST(Image, TruncatedStbFilesAreRefused) {
    const int w = 36, h = 5;
    const std::vector<unsigned char> px3 = test_pixels(w, h, 3), px4 = test_pixels(w, h, 4);
    std::vector<float> hdr(size_t(w) * h * 3);
    for (size_t i = 0; i < hdr.size(); ++i) hdr[i] = px3[i] / 32.f + 0.01f;
    struct Case {
        std::string name;
        std::function<bool(const char *)> write;
    };
    const Case cases[] = {
        {"rgb.png", [&](const char *p) { return stbi_write_png(p, w, h, 3, px3.data(), w * 3) != 0; }},
        {"rgb.bmp", [&](const char *p) { return stbi_write_bmp(p, w, h, 3, px3.data()) != 0; }},
        {"rgba.bmp", [&](const char *p) { return stbi_write_bmp(p, w, h, 4, px4.data()) != 0; }},
        {"rgb.tga", [&](const char *p) {
             stbi_write_tga_with_rle = 0;
             return stbi_write_tga(p, w, h, 3, px3.data()) != 0;
         }},
        {"rle.tga", [&](const char *p) {
             stbi_write_tga_with_rle = 1;
             return stbi_write_tga(p, w, h, 4, px4.data()) != 0;
         }},
        {"rle.hdr", [&](const char *p) { return stbi_write_hdr(p, w, h, 3, hdr.data()) != 0; }},
        {"flat.hdr", [&](const char *p) { return stbi_write_hdr(p, 5, 7, 3, hdr.data()) != 0; }},  // < 8 wide: flat
        {"rgb.ppm", [&](const char *p) {
             std::ofstream(p, std::ios::binary) << "P6\n# neepp\n" << w << " " << h << "\n255\n"
                                                << std::string(px3.begin(), px3.end());
             return true;
         }},
        {"gray16.pgm", [&](const char *p) {
             std::ofstream(p, std::ios::binary) << "P5 " << w << " " << h << " 65535\n"
                                                << std::string(px3.begin(), px3.begin() + 2 * w * h);
             return true;
         }},
    };
    for (const Case &c : cases) {
        const std::string path = temp_path("cut_" + c.name);
        ASSERT_TRUE(c.write(path.c_str())) << c.name;
        const std::string good = read_bytes(path);
        ASSERT_EQ(read_message(path), "(read)") << c.name;
        const Image img = read_image(path);
        EXPECT_EQ(img.height, c.name == "flat.hdr" ? 7 : h) << c.name;
        if (c.name.find(".hdr") == std::string::npos && c.name != "gray16.pgm") {  // 8-bit: the codes back
            const std::vector<unsigned char> &expected = img.channels == 4 ? px4 : px3;
            for (int x = 0; x < img.width; ++x)
                EXPECT_FLOAT_EQ(img.at(x, h - 1, 1) * 255.f, expected[(size_t(h - 1) * w + x) * img.channels + 1])
                    << c.name << " x " << x;
        }
        expect_every_cut_refused(path, good);
        std::filesystem::remove(path);
    }
}

// Where the pixels are stored plainly the header says how many bytes they take: a file with fewer is refused
// from its header, saying so; where they are run-length coded, by stb_image reading past the end (which,
// for an HDR scan line cut short, stb_image 2.27 would otherwise do forever).
TEST(Image, TruncatedStbFilesSayWhy) {
    const int w = 36, h = 5;
    const std::vector<unsigned char> px = test_pixels(w, h, 3);
    std::vector<float> hdr(size_t(w) * h * 3);
    for (size_t i = 0; i < hdr.size(); ++i) hdr[i] = px[i] / 32.f + 0.01f;
    const std::string path = temp_path("why.img");
    auto cut_message = [&](double fraction) {
        const std::string good = read_bytes(path);
        return write_and_read_message(path, good.substr(0, size_t(good.size() * fraction)));
    };
    stbi_write_bmp(path.c_str(), w, h, 3, px.data());
    std::string msg = cut_message(0.5);
    EXPECT_NE(msg.find("its BMP header asks for 36x5 pixels, which need 594 bytes"), std::string::npos) << msg;
    stbi_write_tga_with_rle = 0;
    stbi_write_tga(path.c_str(), w, h, 3, px.data());
    msg = cut_message(0.9);
    EXPECT_NE(msg.find("its TGA header asks for 36x5 pixels, which need 558 bytes"), std::string::npos) << msg;
    stbi_write_tga_with_rle = 1;
    stbi_write_tga(path.c_str(), w, h, 3, px.data());
    msg = cut_message(0.7);
    EXPECT_NE(msg.find("the file ends before its TGA image data does"), std::string::npos) << msg;
    stbi_write_hdr(path.c_str(), w, h, 3, hdr.data());
    msg = cut_message(0.7);
    EXPECT_NE(msg.find("the file ends before its Radiance HDR image data does"), std::string::npos) << msg;
    std::filesystem::remove(path);
}

// A header asking for a huge image from a small file is refused from the header, naming the size, before
// stb_image allocates it (up to 2 GB each).
TEST(Image, StbHeadersAskingForHugeImagesAreRefused) {
    const int w = 36, h = 5;
    const std::vector<unsigned char> px = test_pixels(w, h, 3);
    const std::string path = temp_path("huge.img");
    auto patched = [&](auto write, size_t at, const std::string &bytes) {
        write();
        std::string good = read_bytes(path);
        good.replace(at, bytes.size(), bytes);
        return good;
    };
    auto le = [](uint32_t v, int n) {
        std::string s;
        for (int i = 0; i < n; ++i) s += char(v >> (8 * i));
        return s;
    };
    struct Case {
        std::string bytes, expected;
    };
    const auto bmp = [&] { stbi_write_bmp(path.c_str(), w, h, 3, px.data()); };
    const auto tga = [&] { stbi_write_tga(path.c_str(), w, h, 3, px.data()); };
    stbi_write_tga_with_rle = 0;
    std::vector<Case> cases = {
        {patched(bmp, 18, le(30000, 4) + le(30000, 4)), "BMP header asks for 30000x30000 pixels"},
        {patched(bmp, 22, le(uint32_t(-20000), 4)), "BMP header asks for 36x20000 pixels"},  // top-down rows
        {patched(bmp, 22, le(0x80000000u, 4)), "BMP header asks for 36x2147483648 pixels"},
        {patched(bmp, 28, le(2, 2)), "2 bits a pixel"},
        {patched(tga, 12, le(65535, 2) + le(65535, 2)), "TGA header asks for 65535x65535 pixels"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 30000\n" + std::string(64, '\x02'),
         "Radiance HDR header asks for 30000x30000 pixels, which need at least"},
        {"#?RGBE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100 +X 5\n" + std::string(64, '\x01'),
         "Radiance HDR header asks for 5x100 pixels, which need 2043 bytes of the file, but it has 107"},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 30\n" + std::string(64, '\x01'), "30x0 pixels: no image"},
        {"P6\n30000 30000\n255\n" + std::string(64, 'x'), "PNM header asks for 30000x30000 pixels"},
        {"P5\n99999999999999999999999 2\n255\n" + std::string(64, 'x'), "PNM header asks for"},
        {"P5\n#" + std::string(200, 'c') + "\n2 2\n255\nxxxx", "PNM header is 213 bytes long"},
        {"GIF89a" + le(30000, 2) + le(30000, 2) + std::string(64, '\0'), "GIF images are not read"},
        {"8BPS" + std::string(64, '\0'), "Photoshop (PSD) images are not read"},
        {"\xff\xff\xd8" + std::string(64, '\0'), "Not a JPEG file"},
        {"not an image at all", "not an image format neepp reads"},
    };
    // A PNG whose IHDR asks for 30000x30000 RGB (2.7 GB) from some 200 bytes of deflated data.
    stbi_write_png(path.c_str(), w, h, 3, px.data(), w * 3);
    std::string png = read_bytes(path);
    png.replace(16, 8, std::string("\0\0\x75\x30\0\0\x75\x30", 8));
    cases.push_back({png, "PNG header asks for 30000x30000 pixels (2700000000 bytes), more than its"});
    for (const Case &c : cases) {
        const std::string msg = write_and_read_message(path, c.bytes);
        if (c.expected.empty()) {
            EXPECT_NE(msg.find(path), std::string::npos) << msg;
            continue;
        }
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find(c.expected), std::string::npos) << c.expected << ": " << msg;
    }
    std::filesystem::remove(path);
}

namespace {

// An RGB image as JPEG through libjpeg: baseline, progressive and/or arithmetic-coded (what stb_image_write
// cannot make).
std::string libjpeg_encode(int w, int h, const std::vector<unsigned char> &rgb, bool progressive, bool arithmetic) {
    jpeg_compress_struct c;
    jpeg_error_mgr err;
    c.err = jpeg_std_error(&err);
    jpeg_create_compress(&c);
    unsigned char *out = nullptr;
    unsigned long size = 0;
    jpeg_mem_dest(&c, &out, &size);
    c.image_width = JDIMENSION(w), c.image_height = JDIMENSION(h), c.input_components = 3, c.in_color_space = JCS_RGB;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 90, TRUE);
    if (progressive) jpeg_simple_progression(&c);
    c.arith_code = arithmetic;
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < c.image_height) {
        JSAMPROW row = const_cast<unsigned char *>(&rgb[size_t(c.next_scanline) * w * 3]);
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    std::string bytes(reinterpret_cast<const char *>(out), size);
    jpeg_destroy_compress(&c);
    std::free(out);
    return bytes;
}

}  // namespace

// libjpeg decodes a JPEG that ends early, or whose scan breaks off at a marker, with a warning and the rest
// of the image gray: those are errors, for baseline, progressive and arithmetic-coded files alike.
TEST(Image, TruncatedJpegsAreRefused) {
    const int w = 64, h = 48;
    const std::vector<unsigned char> px = test_pixels(w, h, 3);
    const std::string path = temp_path("cut.jpg");
    ASSERT_TRUE(stbi_write_jpg(path.c_str(), w, h, 3, px.data(), 90));
    const std::string stb = read_bytes(path);
    const std::pair<const char *, std::string> files[] = {
        {"stb_image_write baseline", stb},
        {"baseline", libjpeg_encode(w, h, px, false, false)},
        {"progressive", libjpeg_encode(w, h, px, true, false)},
        {"arithmetic", libjpeg_encode(w, h, px, false, true)},
        {"progressive arithmetic", libjpeg_encode(w, h, px, true, true)},
    };
    for (const auto &[name, good] : files) {
        SCOPED_TRACE(name);
        ASSERT_EQ(write_and_read_message(path, good), "(read)");
        expect_every_cut_refused(path, good);
        const std::string msg = write_and_read_message(path, good.substr(0, good.size() * 3 / 4));
        EXPECT_NE(msg.find("Premature end of JPEG file"), std::string::npos) << msg;
    }
    // Cut inside the scan, then ended properly: libjpeg meets the end-of-image marker in the middle of the scan.
    const std::string msg = write_and_read_message(path, stb.substr(0, stb.size() * 3 / 5) + "\xff\xd9");
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("premature end of data segment"), std::string::npos) << msg;
    std::filesystem::remove(path);
}

// Arithmetic coding has no floor of bits a block (a scan may end early, zeros implied): a header asking
// for more than 64 blocks a byte of the file is refused before libjpeg allocates the image.
TEST(Image, ArithmeticJpegAskingForAHugeImageIsRefused) {
    const int w = 64, h = 48;
    std::string bytes = libjpeg_encode(w, h, test_pixels(w, h, 3), false, true);
    const size_t sof = bytes.find("\xff\xc9");  // start of frame, sequential arithmetic-coded
    ASSERT_NE(sof, std::string::npos);
    bytes.replace(sof + 5, 4, std::string("\x1f\x40\x1f\x40", 4));  // 8000 rows, 8000 columns
    const std::string path = temp_path("huge_arith.jpg");
    const std::string msg = write_and_read_message(path, bytes);
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("asks for 8000x8000 pixels"), std::string::npos) << msg;
    EXPECT_NE(msg.find("64 blocks a byte"), std::string::npos) << msg;
    std::filesystem::remove(path);
}
