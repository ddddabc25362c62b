#include "neepp/io/image.h"

#include <IexBaseExc.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfThreading.h>
#include <fmt/format.h>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#ifdef NEEPP_HAVE_LIBJPEG
#include <csetjmp>
#include <jpeglib.h>
#include <jerror.h>  // the JWRN_ codes
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <thread>
#include "neepp/io/atomic_file.h"
#include "neepp/io/stb_file.h"

namespace neepp {

namespace {

using namespace image_check;

enum class FileKind { Exr, Jpeg, Other };

FileKind sniff(const std::string &path) {
    std::unique_ptr<FILE, int (*)(FILE *)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) fail(path, "cannot open file");
    unsigned char magic[4] = {};
    size_t n = std::fread(magic, 1, 4, f.get());
    static const unsigned char kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
    if (n == 4 && std::memcmp(magic, kExrMagic, 4) == 0) return FileKind::Exr;
    // Start-of-image, or 0xff fill bytes before it, which stb_image (not libjpeg) would read as JPEG: libjpeg
    // refuses those, naming them, rather than stb_image decoding them unchecked.
    if (n >= 2 && magic[0] == 0xff && (magic[1] == 0xd8 || magic[1] == 0xff)) return FileKind::Jpeg;
    return FileKind::Other;
}

#ifdef NEEPP_HAVE_LIBJPEG
// Mitsuba decodes JPEG with libjpeg(-turbo) at its default settings (islow IDCT, fancy upsampling);
// stb_image's decoder differs from it by up to 3/255 on a few percent of the values, so when the build
// links libjpeg we decode with it to get Mitsuba's texels exactly.
struct JpegError {
    jpeg_error_mgr mgr;
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX] = {};
};

ImageBytes read_jpeg(const std::string &path) {
    std::unique_ptr<FILE, int (*)(FILE *)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) fail(path, "cannot open file");
    jpeg_decompress_struct cinfo;
    JpegError err;
    cinfo.err = jpeg_std_error(&err.mgr);
    err.mgr.error_exit = [](j_common_ptr c) {
        auto *e = reinterpret_cast<JpegError *>(c->err);
        e->mgr.format_message(c, e->message);
        std::longjmp(e->jump, 1);
    };
    // libjpeg decodes past a loss of data with a warning (the file ending early, a marker or a bad code in the
    // middle of a scan), the rest of the image gray or garbage: those warnings are errors here. Others (extra
    // bytes before a marker, an unusual JFIF version) are harmless: the image is read, without libjpeg's
    // message on stderr.
    err.mgr.emit_message = [](j_common_ptr c, int level) {
        const int code = c->err->msg_code;
        if (level < 0 && (code == JWRN_JPEG_EOF || code == JWRN_HIT_MARKER || code == JWRN_HUFF_BAD_CODE ||
                          code == JWRN_ARITH_BAD_CODE || code == JWRN_MUST_RESYNC))
            c->err->error_exit(c);
    };
    ImageBytes img;
    if (setjmp(err.jump)) {  // libjpeg reports errors by longjmp to here
        jpeg_destroy_decompress(&cinfo);
        fail(path, std::string("corrupt JPEG file: ") + err.message);
    }
    jpeg_create_decompress(&cinfo);
    jpeg_stdio_src(&cinfo, f.get());
    jpeg_read_header(&cinfo, TRUE);
    // libjpeg decodes a file that ends early with a warning, the rest gray, so a damaged header asking for
    // a huge image from a few bytes costs all its pixels (fuzz_image met a 199-byte file asking for
    // 16725x21334 RGB: 1 GB of codes, 4 GB as floats). With Huffman coding each 8x8 block of each
    // component takes at least one bit (its DC code), so a complete file holds at least one byte per 8
    // blocks: one asking for more blocks is refused before libjpeg allocates anything for them. This holds for
    // progressive files too (their first DC scans code every block). Arithmetic coding has no such floor (a
    // scan may end early, zeros implied, and a near-constant image takes a tiny fraction of a bit a block), so
    // there a limit is set instead: 64 blocks a byte (a 10 kB RGB file up to 13 megapixels), beyond any real
    // arithmetic-coded photograph, keeps what such a file may cost in proportion to its size.
    {
        const uint64_t blocks_per_byte = cinfo.arith_code ? 64 : 8;
        std::error_code ec;
        const uintmax_t file_size = std::filesystem::file_size(path, ec);
        uint64_t blocks = 0;
        for (int c = 0; c < cinfo.num_components; ++c) {
            const jpeg_component_info &comp = cinfo.comp_info[c];
            const uint64_t w = (uint64_t(cinfo.image_width) * comp.h_samp_factor + 8 * cinfo.max_h_samp_factor - 1) /
                               (8 * uint64_t(std::max(1, cinfo.max_h_samp_factor)));
            const uint64_t h = (uint64_t(cinfo.image_height) * comp.v_samp_factor + 8 * cinfo.max_v_samp_factor - 1) /
                               (8 * uint64_t(std::max(1, cinfo.max_v_samp_factor)));
            blocks += w * h;
        }
        if (!ec && blocks > blocks_per_byte * uint64_t(file_size)) {
            const std::string what = fmt::format(
                "its JPEG header asks for {}x{} pixels of {} components ({} blocks of 8x8), more than its {} bytes "
                "can hold ({}): a damaged header or a truncated file",
                cinfo.image_width, cinfo.image_height, cinfo.num_components, blocks, file_size,
                cinfo.arith_code ? "at most 64 blocks a byte are read from an arithmetic-coded file"
                                 : "at least one bit a block");
            jpeg_destroy_decompress(&cinfo);
            fail(path, what);
        }
    }
    jpeg_start_decompress(&cinfo);
    const int w = int(cinfo.output_width), h = int(cinfo.output_height), n = cinfo.output_components;
    if (n != 1 && n != 3) {
        jpeg_destroy_decompress(&cinfo);
        fail(path, "unsupported JPEG color layout (only gray and RGB)");
    }
    img.width = w, img.height = h, img.channels = n;
    img.data.resize(size_t(w) * h * n);
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW row = &img.data[size_t(cinfo.output_scanline) * w * n];  // decoded in place
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    return img;
}
#endif

// Which of the file's channels become the image's: RGB(A) if present, else Y(A), else a lone channel.
std::vector<std::string> pick_exr_channels(const Imf::ChannelList &list, const std::string &path) {
    auto has = [&](const char *name) { return list.findChannel(name) != nullptr; };
    std::vector<std::string> names;
    if (has("R") && has("G") && has("B"))
        names = {"R", "G", "B"};
    else if (has("Y"))
        names = {"Y"};
    else {
        std::string all;
        int count = 0;
        for (auto it = list.begin(); it != list.end(); ++it, ++count) all += std::string(" ") + it.name();
        if (count != 1) fail(path, "unsupported OpenEXR channel layout:" + all);
        return {list.begin().name()};
    }
    if (has("A")) names.push_back("A");
    return names;
}

// OpenEXR reads a header attribute of a string, vector, preview, ID manifest or unknown (opaque) type by
// first allocating the size the attribute's size field claims (a 32-bit count, up to 2 GB; a string's is
// zero-filled) and then reading that many bytes, so a damaged header costs that allocation before the
// read fails: under AddressSanitizer 78 % of fuzz_image's time went there (each allocation's shadow
// poisoned and unpoisoned). This walks the header(s) as OpenEXR 3.1 reads them (Header::readFrom and
// each type's readValueFrom: names and type names of at most 255 characters and a zero; a channel list
// read up to its empty name and the other known types' values at their fixed sizes, whatever their size
// fields say; a multi-part file's headers until an empty one) and refuses an attribute OpenEXR would
// allocate at a size that is negative or larger than what follows it in the file. Anything else odd (a
// name without its zero, an early end) stops the walk and is left to OpenEXR's own checks.
void check_exr_attribute_sizes(const std::string &path) {
    // The bytes OpenEXR reads for a known type's value, whatever its size field says.
    static const std::pair<const char *, int> kFixedSizes[] = {
        {"box2i", 16},   {"box2f", 16}, {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
        {"double", 8},   {"envmap", 1}, {"float", 4},           {"int", 4},         {"keycode", 28},
        {"lineOrder", 1}, {"m33d", 72}, {"m33f", 36},           {"m44d", 128},      {"m44f", 64},
        {"rational", 8}, {"tiledesc", 9}, {"timecode", 8},      {"v2d", 16},        {"v2f", 8},
        {"v2i", 8},      {"v3d", 24},   {"v3f", 12},            {"v3i", 12}};
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    const uintmax_t file_size = std::filesystem::file_size(path, ec);
    unsigned char head[8];
    if (ec || !in.read(reinterpret_cast<char *>(head), sizeof head)) return;
    const bool multipart = head[5] & 0x10;  // the version field's flag 0x1000
    auto read_name = [&](std::string &s) {  // as Xdr::read(is, 255, name) and checkIsNullTerminated
        s.clear();
        for (int i = 0; i < 256; ++i) {
            const int c = in.get();
            if (c == std::char_traits<char>::eof()) return false;
            if (c == 0) return true;
            s += char(c);
        }
        return false;
    };
    for (;;) {  // each part's header
        std::string name, type;
        bool empty = true;
        for (;;) {
            if (!read_name(name)) return;
            if (name.empty()) break;
            empty = false;
            unsigned char b[4];
            if (!read_name(type) || !in.read(reinterpret_cast<char *>(b), sizeof b)) return;
            const int32_t size = int32_t(uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
            if (type == "chlist") {  // entries (a name, then 16 bytes) up to an empty name
                std::string channel;
                for (;;) {
                    if (!read_name(channel)) return;
                    if (channel.empty()) break;
                    in.seekg(16, std::ios::cur);
                }
                continue;
            }
            const auto fixed = std::find_if(std::begin(kFixedSizes), std::end(kFixedSizes),
                                            [&](const auto &t) { return type == t.first; });
            if (fixed != std::end(kFixedSizes)) {
                in.seekg(fixed->second, std::ios::cur);
                continue;
            }
            const std::streamoff at = in.tellg();
            if (at < 0) return;
            const uintmax_t left = file_size > uintmax_t(at) ? file_size - uintmax_t(at) : 0;
            if (size < 0 || uintmax_t(size) > left)
                fail(path, fmt::format("its OpenEXR header's attribute '{}' (type '{}') claims {} bytes, but only {} "
                                       "bytes of the file follow it (a damaged or truncated header)",
                                       printable(name), printable(type), size, left));
            in.seekg(type == "floatvector" ? size / 4 * 4 : size, std::ios::cur);  // whole floats
        }
        if (!multipart || empty) return;
    }
}

Image read_exr(const std::string &path) {
    try {
        // OpenEXR decodes the file's blocks on its global thread pool (InputFile's default), which is empty
        // until given threads (on one thread, a large environment map is a good part of a scene's load).
        [[maybe_unused]] static const bool pool = [] {
            Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
            // A header may claim any data window, and the file is opened (its table of chunk offsets
            // allocated per line) before a check of ours could run: OpenEXR's own sanity check refuses
            // a window wider or taller than the film may be.
            Imf::Header::setMaxImageSize(kMaxImageSide, kMaxImageSide);
            return true;
        }();
        check_exr_attribute_sizes(path);
        Imf::InputFile file(path.c_str());
        const Imath::Box2i dw = file.header().dataWindow();
        const int64_t width = int64_t(dw.max.x) - dw.min.x + 1, height = int64_t(dw.max.y) - dw.min.y + 1;
        if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
            fail(path, fmt::format("its data window is {}x{} pixels; at most {} on a side are read (as a film's)", width,
                                   height, kMaxImageSide));
        // Before the pixels are allocated: a damaged header asking for a window the file's data does not
        // cover would otherwise cost gigabytes of zeros before the read fails.
        if (!file.isComplete()) fail(path, "the file is incomplete: its chunks do not cover its data window (truncated or damaged)");
        std::vector<std::string> names = pick_exr_channels(file.header().channels(), path);
        Image img(dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1, int(names.size()));
        const size_t xstride = sizeof(float) * img.channels, ystride = xstride * img.width;
        Imf::FrameBuffer fb;
        // OpenEXR converts half (or uint) channels to the FLOAT slices on read.
        for (size_t c = 0; c < names.size(); ++c)
            fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, img.data.data() + c, dw, xstride, ystride));
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        return img;
    } catch (const Iex::BaseExc &e) {  // OpenEXR's own errors; ours already name the path
        fail(path, fmt::format("cannot read OpenEXR file: {}", e.what()));
    }
}

template <typename T>
Image image_from_stb(T *pixels, int w, int h, int n, float scale, bool srgb) {
    Image img(w, h, n);
    for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(pixels[i]) * scale;
    img.srgb_encoded = srgb;
    stbi_image_free(pixels);
    return img;
}

[[noreturn]] void fail_stb(const std::string &path) {
    const char *why = stbi_failure_reason();
    fail(path, fmt::format("unsupported or corrupt image file ({})", why ? why : "unknown error"));
}


// Runs an stb_image load through StbInput; fails naming the path if it read past the end or failed.
template <typename Load>
auto load_stb(const StbFile &f, Load load, int &w, int &h, int &n) {
    StbInput in{&f.bytes};
    static const stbi_io_callbacks callbacks{&StbInput::read, &StbInput::skip, &StbInput::eof};
    auto *px = load(&callbacks, &in, &w, &h, &n, 0);
    if (in.past_end) {
        stbi_image_free(px);
        fail(f.path, fmt::format("the file ends before its {} image data does (a truncated or damaged file)",
                                 format_name(f.format)));
    }
    if (!px) fail_stb(f.path);
    if (w <= 0 || h <= 0 || n < 1 || n > 4) {
        stbi_image_free(px);
        fail(f.path, fmt::format("stb_image read it as {}x{} pixels of {} channels: no image", w, h, n));
    }
    return px;
}

bool is_8_bit(const StbFile &f) { return f.format != StbFormat::Hdr && !f.header.sixteen_bit; }

ImageBytes read_stb_8_bit(const StbFile &f) {
    int w = 0, h = 0, n = 0;
    stbi_uc *px = load_stb(f, stbi_load_from_callbacks, w, h, n);
    ImageBytes img;
    img.width = w, img.height = h, img.channels = n;
    img.data.assign(px, px + size_t(w) * h * n);
    stbi_image_free(px);
    return img;
}

// stbi_loadf is avoided for integer files: it applies a gamma-2.2 curve instead of keeping the codes.
Image read_stb(const StbFile &f) {
    int w = 0, h = 0, n = 0;
    if (f.format == StbFormat::Hdr) {
        float *px = load_stb(f, stbi_loadf_from_callbacks, w, h, n);
        return image_from_stb(px, w, h, n, 1.f, false);
    }
    stbi_us *px = load_stb(f, stbi_load_16_from_callbacks, w, h, n);
    return image_from_stb(px, w, h, n, 1.f / 65535.f, true);
}

// 8-bit codes as Image's normalized floats. Multiplying by the reciprocal (not dividing) reproduces
// Dr.Jit's 8-bit texel decode bit for bit.
Image image_from_bytes(const ImageBytes &bytes) {
    Image img(bytes.width, bytes.height, bytes.channels);
    for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(bytes.data[i]) * (1.f / 255.f);
    img.srgb_encoded = true;
    return img;
}

// The file's kind after checking that it exists.
FileKind kind_of(const std::string &path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) fail(path, "no such file");
    return sniff(path);
}

void check_writable(const std::string &path, const Image &img) {
    if (img.width <= 0 || img.height <= 0 || img.channels < 1 || img.channels > 4 ||
        img.data.size() != size_t(img.width) * img.height * img.channels)
        fail(path, fmt::format("cannot write an invalid image ({}x{}, {} channels, {} values)", img.width,
                               img.height, img.channels, img.data.size()));
}

}  // namespace

std::optional<ImageBytes> read_image_bytes(const std::string &path) {
    switch (kind_of(path)) {
        case FileKind::Exr: return std::nullopt;
#ifdef NEEPP_HAVE_LIBJPEG
        case FileKind::Jpeg: return read_jpeg(path);
#endif
        default: {
            const StbFile f = open_stb(path);
            if (!is_8_bit(f)) return std::nullopt;
            return read_stb_8_bit(f);
        }
    }
}

Image read_image(const std::string &path) {
    switch (kind_of(path)) {
        case FileKind::Exr: return read_exr(path);
#ifdef NEEPP_HAVE_LIBJPEG
        case FileKind::Jpeg: return image_from_bytes(read_jpeg(path));
#endif
        default: {
            const StbFile f = open_stb(path);
            return is_8_bit(f) ? image_from_bytes(read_stb_8_bit(f)) : read_stb(f);
        }
    }
}

std::vector<std::string> channel_names(int channels) {
    switch (channels) {
        case 1: return {"Y"};
        case 2: return {"Y", "A"};
        case 3: return {"R", "G", "B"};
        case 4: return {"R", "G", "B", "A"};
        default: return {};
    }
}

void write_exr(const std::string &path, const Image &img, bool half) {
    check_writable(path, img);
    const std::vector<std::string> names = channel_names(img.channels);
    const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
    std::vector<Imath::half> halves;
    if (half) halves.assign(img.data.begin(), img.data.end());
    const size_t elem = half ? sizeof(Imath::half) : sizeof(float);
    char *base = half ? reinterpret_cast<char *>(halves.data())
                      : reinterpret_cast<char *>(const_cast<float *>(img.data.data()));
    try {
        Imf::Header header(img.width, img.height);
        header.compression() = Imf::ZIP_COMPRESSION;
        Imf::FrameBuffer fb;
        const size_t xstride = elem * img.channels, ystride = xstride * img.width;
        for (size_t c = 0; c < names.size(); ++c) {
            header.channels().insert(names[c], Imf::Channel(type));
            fb.insert(names[c], Imf::Slice(type, base + c * elem, xstride, ystride));
        }
        write_file_atomically(path, [&](const std::string &tmp) {
            Imf::OutputFile file(tmp.c_str(), header);
            file.setFrameBuffer(fb);
            file.writePixels(img.height);
        });
    } catch (const std::exception &e) {
        fail(path, fmt::format("cannot write OpenEXR file: {}", e.what()));
    }
}

void write_png_srgb(const std::string &path, const Image &img, float exposure) {
    check_writable(path, img);
    const int color = img.color_channels();
    std::vector<unsigned char> bytes(img.data.size());
    for (size_t i = 0; i < img.data.size(); ++i) {
        const bool alpha = int(i % img.channels) >= color;
        float v = alpha ? img.data[i] : img.data[i] * exposure;
        v = std::isnan(v) ? 0.f : std::clamp(v, 0.f, 1.f);
        if (!alpha) v = linear_to_srgb(v);
        bytes[i] = (unsigned char)(v * 255.f + 0.5f);
    }
    write_file_atomically(path, [&](const std::string &tmp) {
        if (!stbi_write_png(tmp.c_str(), img.width, img.height, img.channels, bytes.data(), img.width * img.channels))
            fail(path, "cannot write PNG file");
    });
}

float srgb_to_linear(float v) {
    const double x = v;
    return float(x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4));
}

float linear_to_srgb(float v) {
    const double x = v;
    return float(x <= 0.0031308 ? x * 12.92 : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055);
}

}  // namespace neepp
