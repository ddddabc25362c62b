#include "neepp/io/stb_file.h"

#include <fmt/format.h>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace neepp::image_check {

[[noreturn]] void fail(const std::string &path, const std::string &what) {
    throw std::runtime_error(fmt::format("image '{}': {}", path, what));
}

std::string printable(const std::string &s) {
    std::string out;
    for (char c : s.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
    return s.size() > 40 ? out + "..." : out;
}

const char *format_name(StbFormat f) {
    switch (f) {
        case StbFormat::Png: return "PNG";
        case StbFormat::Bmp: return "BMP";
        case StbFormat::Gif: return "GIF";
        case StbFormat::Psd: return "Photoshop (PSD)";
        case StbFormat::Pic: return "Softimage PIC";
        case StbFormat::Jpeg: return "JPEG";
        case StbFormat::Pnm: return "PNM";
        case StbFormat::Hdr: return "Radiance HDR";
        case StbFormat::Tga: return "TGA";
        default: return "unknown";
    }
}

namespace {

// A file's bytes, read the way stb_image reads them through stbi_io_callbacks: past the end, as '\n'
// (see StbInput).
struct Bytes {
    const std::string &s;
    unsigned operator[](size_t i) const { return i < s.size() ? (unsigned char)s[i] : '\n'; }
    uint32_t le16(size_t i) const { return (*this)[i] | (*this)[i + 1] << 8; }
    uint32_t le32(size_t i) const { return le16(i) | le16(i + 2) << 16; }
    uint32_t be32(size_t i) const {
        return (*this)[i] << 24 | (*this)[i + 1] << 16 | (*this)[i + 2] << 8 | (*this)[i + 3];
    }
    bool starts(size_t i, const char *magic) const {
        for (size_t k = 0; magic[k]; ++k)
            if ((*this)[i + k] != (unsigned char)magic[k]) return false;
        return true;
    }
};

bool stb_tga_test(const Bytes &b) {  // stbi__tga_test: TGA has no magic number, only plausible fields
    const unsigned color_type = b[1], image_type = b[2];
    if (color_type > 1) return false;
    if (color_type == 1) {
        if (image_type != 1 && image_type != 9) return false;
        const unsigned palette_bits = b[7];
        if (palette_bits != 8 && palette_bits != 15 && palette_bits != 16 && palette_bits != 24 && palette_bits != 32)
            return false;
    } else if (image_type != 2 && image_type != 3 && image_type != 10 && image_type != 11) {
        return false;
    }
    if (b.le16(12) < 1 || b.le16(14) < 1) return false;
    const unsigned bpp = b[16];
    if (color_type == 1 && bpp != 8 && bpp != 16) return false;
    return bpp == 8 || bpp == 15 || bpp == 16 || bpp == 24 || bpp == 32;
}

StbFormat stb_format(const Bytes &b) {
    if (b.starts(0, "\x89PNG\r\n\x1a\n")) return StbFormat::Png;
    if (b.starts(0, "BM")) {
        const uint32_t header = b.le32(14);
        if (header == 12 || header == 40 || header == 56 || header == 108 || header == 124) return StbFormat::Bmp;
    }
    if (b.starts(0, "GIF8") && (b[4] == '7' || b[4] == '9') && b[5] == 'a') return StbFormat::Gif;
    if (b.starts(0, "8BPS")) return StbFormat::Psd;
    if (b.starts(0, "\x53\x80\xf6\x34") && b.starts(88, "PICT")) return StbFormat::Pic;
    if (b[0] == 0xff) {  // a marker: 0xff, any fill bytes 0xff, then start-of-image
        size_t i = 1;
        while (i < b.s.size() && b[i] == 0xff) ++i;
        if (b[i] == 0xd8) return StbFormat::Jpeg;
    }
    if (b[0] == 'P' && (b[1] == '5' || b[1] == '6')) return StbFormat::Pnm;
    if (b.starts(0, "#?RADIANCE\n") || b.starts(0, "#?RGBE\n")) return StbFormat::Hdr;
    if (stb_tga_test(b)) return StbFormat::Tga;
    return StbFormat::Unknown;
}


StbHeader bmp_header(const Bytes &b) {  // stbi__bmp_parse_header and stbi__bmp_load
    StbHeader h;
    const uint32_t offset = b.le32(10), header = b.le32(14);
    uint32_t bpp, compression = 0;
    if (header == 12) {
        h.width = b.le16(18), h.height = b.le16(20), bpp = b.le16(24);
    } else {
        h.width = b.le32(18), h.height = std::abs(int64_t(int32_t(b.le32(22)))), bpp = b.le16(28);
        compression = b.le32(30);
    }
    // stb_image refuses run-length (1, 2) and JPEG/PNG (4, 5) BMPs and a negative offset from the header.
    if ((compression != 0 && compression != 3) || int32_t(offset) < 0) return h;
    uint64_t row;  // a row's bytes, then padding to a multiple of 4
    switch (bpp) {
        case 1: row = (uint64_t(h.width) + 7) / 8; break;
        case 4: row = (uint64_t(h.width) + 1) / 2; break;
        case 8: case 16: case 24: case 32: row = uint64_t(h.width) * (bpp / 8); break;
        default: throw std::runtime_error(fmt::format("its BMP header gives {} bits a pixel (only 1, 4, 8, 16, 24 "
                                                      "and 32 are read)", bpp));
    }
    const uint64_t stride = (row + 3) / 4 * 4;
    // The pixels start at the header's offset; the last row's padding may be left out.
    h.need = h.height > 0 ? uint64_t(offset) + (uint64_t(h.height) - 1) * stride + row : offset;
    h.checked = true;
    return h;
}

StbHeader tga_header(const Bytes &b) {  // stbi__tga_load
    StbHeader h;
    const unsigned id_length = b[0], indexed = b[1], image_type = b[2], palette_bits = b[7], bpp = b[16];
    h.width = b.le16(12), h.height = b.le16(14);
    uint64_t start = 18 + id_length;
    if (indexed) start += b.le16(3) + uint64_t(b.le16(5)) * ((palette_bits + 7) / 8);  // skipped, then the palette
    const uint64_t pixel = (bpp + 7) / 8, pixels = uint64_t(h.width) * uint64_t(h.height);
    if (image_type >= 8) {  // run-length coded: packets of a count byte and one pixel, up to 128 pixels each
        h.need = start + (pixels + 127) / 128 * (1 + pixel);
        h.exact = false;
    } else {
        h.need = start + pixels * pixel;
    }
    h.checked = true;
    return h;
}

StbHeader hdr_header(const Bytes &b) {  // stbi__hdr_load
    StbHeader h;
    size_t at = 0;
    auto line = [&] {  // stbi__hdr_gettoken: up to '\n', at most 1023 characters kept
        std::string s;
        while (at < b.s.size() && b[at] != '\n') {
            if (s.size() < 1023) s += char(b[at]);
            ++at;
        }
        ++at;
        return s;
    };
    line();  // "#?RADIANCE" or "#?RGBE", as stb_format saw
    bool rgbe = false;
    for (std::string s; at < b.s.size() && !(s = line()).empty();) rgbe = rgbe || s == "FORMAT=32-bit_rle_rgbe";
    const std::string size = line();
    if (!rgbe || size.compare(0, 3, "-Y ") != 0) return h;  // refused by stb_image
    char *end = nullptr;
    h.height = int(std::strtol(size.c_str() + 3, &end, 10));
    while (*end == ' ') ++end;
    if (std::strncmp(end, "+X ", 3) != 0) return h;
    h.width = int(std::strtol(end + 3, nullptr, 10));
    if (h.width <= 0 || h.height <= 0) {
        h.checked = true;
        return h;
    }
    // Scan lines 8 to 32767 pixels wide may be run-length coded: a 4-byte mark (2, 2, width), then each of the
    // 4 components as runs (2 bytes for up to 127 pixels) or literals. Otherwise (and when the first scan
    // line has no mark, which makes stb_image read the whole image so) 4 bytes a pixel.
    const uint64_t pixels = uint64_t(h.width) * uint64_t(h.height);
    if (h.width >= 8 && h.width < 32768 && b[at] == 2 && b[at + 1] == 2 && !(b[at + 2] & 0x80)) {
        h.need = at + uint64_t(h.height) * (4 + 4 * 2 * ((uint64_t(h.width) + 126) / 127));
        h.exact = false;
    } else {
        h.need = at + 4 * pixels;
    }
    h.checked = true;
    return h;
}

StbHeader pnm_header(const Bytes &b) {  // stbi__pnm_info and stbi__pnm_load (binary P5 gray, P6 RGB)
    StbHeader h;
    size_t at = 2;
    unsigned c = b[at++];
    auto skip_space = [&] {
        for (;;) {
            while (at <= b.s.size() && (c == ' ' || (c >= '\t' && c <= '\r'))) c = b[at++];
            if (at > b.s.size() || c != '#') return;
            while (at <= b.s.size() && c != '\n' && c != '\r') c = b[at++];
        }
    };
    auto integer = [&] {
        uint64_t v = 0;
        while (at <= b.s.size() && c >= '0' && c <= '9') {
            v = std::min<uint64_t>(v * 10 + (c - '0'), uint64_t(1) << 40);  // no overflow; stb_image refuses past 2^24
            c = b[at++];
        }
        return v;
    };
    skip_space();
    h.width = int64_t(integer());
    skip_space();
    h.height = int64_t(integer());
    skip_space();
    const uint64_t max_value = integer();
    if (max_value > 65535) return h;  // refused by stb_image
    // stb_image reads the header twice, the second time from its first buffer of 128 bytes again: a longer
    // header (long comments) would be read the second time from other bytes of the file.
    if (at > 128)
        throw std::runtime_error(fmt::format("its PNM header is {} bytes long; stb_image reads at most 128", at));
    h.sixteen_bit = max_value > 255;
    h.need = at + uint64_t(h.width) * uint64_t(h.height) * (b[1] == '6' ? 3 : 1) * (h.sixteen_bit ? 2 : 1);
    h.checked = true;
    return h;
}

// stb_image reads a PNG's IDAT chunks into one buffer, grown to the size each chunk's header claims (up
// to 2 GB) before the chunk is read, so a damaged length costs that allocation before the read fails (9 %
// of fuzz_image's time once the OpenEXR headers were checked). This walks the chunks up to IEND (each a
// 4-byte big-endian length, a 4-byte type, the data and a 4-byte CRC) and refuses one whose data the
// file does not hold, which stb_image would fail on anyway. Then stb_image allocates the image IHDR asks
// for (up to 1 GB, twice: the inflated rows, then the pixels) before it inflates the IDAT data: deflate
// expands at most 1032 times (a 258-byte match for 2 bits), so IHDR asking for more bytes than the IDAT
// data could inflate to is refused too.
StbHeader png_header(const Bytes &b) {
    StbHeader h;
    const uint64_t file_size = b.s.size();
    uint64_t idat = 0;
    bool ihdr = false;
    for (uint64_t at = 8; at + 8 <= file_size;) {
        const uint32_t length = b.be32(at);
        const std::string type = b.s.substr(at + 4, 4);
        if (type == "IEND") break;
        at += 8;
        if (length > file_size - at)
            throw std::runtime_error(fmt::format("its PNG chunk '{}' claims {} bytes, but only {} bytes of the file "
                                                 "follow it (a damaged or truncated file)",
                                                 printable(type), length, file_size - at));
        if (type == "IHDR" && !ihdr && length >= 13) {
            ihdr = true;
            h.width = b.be32(at), h.height = b.be32(at + 4);
            const unsigned depth = b[at + 8], color = b[at + 9];
            const unsigned channels = color == 2 ? 3 : color == 4 ? 2 : color == 6 ? 4 : 1;
            h.sixteen_bit = depth == 16;
            // At least the pixels' bits (a non-interlaced file adds a filter byte a row).
            h.need = (uint64_t(h.width) * uint64_t(h.height) * channels * depth + 7) / 8;
        }
        if (type == "IDAT") idat += length;
        at += uint64_t(length) + 4;
    }
    if (!ihdr) return h;  // refused by stb_image
    if (h.need > 1032 * idat + 1032)
        throw std::runtime_error(fmt::format("its PNG header asks for {}x{} pixels ({} bytes), more than its {} bytes "
                                             "of image data can inflate to (deflate expands at most 1032 times): a "
                                             "damaged header or a truncated file",
                                             h.width, h.height, h.need, idat));
    h.need = 0;  // not a size of the file: the bound above is the check
    h.exact = false;
    h.checked = true;
    return h;
}


}  // namespace

StbFile open_stb(const std::string &path) {
    StbFile f;
    f.path = path;
    {
        std::ifstream in(path, std::ios::binary | std::ios::ate);
        if (!in) fail(path, "cannot open file");
        const std::streamoff size = in.tellg();
        // stb_image counts a file's bytes in an int.
        if (size < 0 || size >= std::streamoff(INT32_MAX)) fail(path, "cannot read a file of 2 GB or more");
        f.bytes.resize(size_t(size));
        in.seekg(0);
        if (!in.read(f.bytes.data(), size)) fail(path, "cannot read file");
    }
    const Bytes b{f.bytes};
    f.format = stb_format(b);
    switch (f.format) {
        case StbFormat::Png: case StbFormat::Bmp: case StbFormat::Tga: case StbFormat::Hdr: case StbFormat::Pnm: break;
        case StbFormat::Unknown:
            fail(path, "not an image format neepp reads (OpenEXR, PNG, JPEG, Radiance HDR, TGA, BMP, binary PNM)");
        case StbFormat::Jpeg: fail(path, "JPEG is read through libjpeg only");
        default:  // stb_image would read these too, but they are no renderer's textures: not checked, not read
            fail(path, fmt::format("{} images are not read (only OpenEXR, PNG, JPEG, Radiance HDR, TGA, BMP, "
                                   "binary PNM)",
                                   format_name(f.format)));
    }
    try {  // the header readers' errors say what is wrong; the path is added here
        f.header = f.format == StbFormat::Png   ? png_header(b)
                   : f.format == StbFormat::Bmp ? bmp_header(b)
                   : f.format == StbFormat::Tga ? tga_header(b)
                   : f.format == StbFormat::Hdr ? hdr_header(b)
                                                : pnm_header(b);
    } catch (const std::runtime_error &e) {
        fail(path, e.what());
    }
    const StbHeader &h = f.header;
    if (!h.checked) return f;
    if (h.width <= 0 || h.height <= 0)
        fail(path, fmt::format("its {} header gives a size of {}x{} pixels: no image", format_name(f.format), h.width,
                               h.height));
    if (h.need > f.bytes.size())
        fail(path, fmt::format("its {} header asks for {}x{} pixels, which need {}{} bytes of the file, but it has {} "
                               "(a truncated file or a damaged header)",
                               format_name(f.format), h.width, h.height, h.exact ? "" : "at least ", h.need,
                               f.bytes.size()));
    return f;
}

}  // namespace neepp::image_check
