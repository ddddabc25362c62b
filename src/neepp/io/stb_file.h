// stb_image's formats checked before stb_image decodes them (image.cpp): which format a file is, by the
// tests stb_image itself makes; what its header asks for, against the bytes the file holds; and the input
// stb_image reads through, which sees it read past the file's end.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

namespace neepp::image_check {

// std::runtime_error("image '<path>': <what>").
[[noreturn]] void fail(const std::string &path, const std::string &what);
// A name from a damaged header, printable: other bytes as '?', at most 40 characters.
std::string printable(const std::string &s);

// The formats stb_image reads, told apart by the tests stb_image itself makes, in its order
// (stbi__load_main), so that the format checked below is the one stb_image then decodes.
enum class StbFormat { Png, Bmp, Gif, Psd, Pic, Jpeg, Pnm, Hdr, Tga, Unknown };
const char *format_name(StbFormat f);

// stb_image reads a file that ends early as if zeros followed (a truncated BMP, TGA, HDR or PNM loads with
// black or garbage pixels), and it allocates the image its header asks for (up to 2 GB) before reading a
// pixel. So each format's header is read here first, and a file shorter than the bytes its pixels need
// (exactly, for uncompressed data; at the least, for run-length or deflate coded data) is refused before
// stb_image allocates anything. What the header cannot tell (a run-length coded file cut short) is seen as
// stb_image reading past the end (StbInput). Each check mirrors what stb_image 2.27 (Debian's libstb)
// reads; where stb_image refuses a header itself before allocating, the check leaves it to it.
struct StbHeader {
    int64_t width = 0, height = 0;
    uint64_t need = 0;      // bytes of the file its pixels need (at least, where `exact` is false)
    bool exact = true;
    bool sixteen_bit = false;
    bool checked = false;   // false: stb_image refuses this header before allocating
};

// Reading through stbi_io_callbacks shows what reading from memory or a FILE hides: stb_image asking for
// bytes past the file's end. It reads through its own 128-byte buffer (the first read, and every refill
// after: a short read there is the file's end, a read of nothing is stb_image wanting more than the file
// holds) or, for a block of pixels, straight into the image (stbi__getn, whose short read TGA, HDR and PNM
// decoding ignore: the rest of the block would be garbage). Past the end it is given '\n' bytes, not the
// zeros stb_image makes up itself: in a run-length coded HDR scan line a zero count never ends (stb_image
// 2.27 loops forever on a file cut there), and a '\n' ends each HDR header line, so every loop ends. The
// image is refused whenever past_end is set.
struct StbInput {
    const std::string *bytes;
    size_t at = 0;
    const char *buffer = nullptr;  // stb_image's own buffer: where its first read goes
    bool past_end = false;

    static int read(void *user, char *data, int size) {
        auto &in = *static_cast<StbInput *>(user);
        if (!in.buffer) in.buffer = data;
        const size_t left = in.at < in.bytes->size() ? in.bytes->size() - in.at : 0;
        const size_t n = std::min(left, size_t(std::max(size, 0)));
        std::memcpy(data, in.bytes->data() + in.at, n);
        in.at += n;
        if (n == size_t(std::max(size, 0)) || (n > 0 && data == in.buffer)) return int(n);
        in.past_end = true;
        std::memset(data + n, '\n', size_t(size) - n);
        return size;
    }
    static void skip(void *user, int n) {
        auto &in = *static_cast<StbInput *>(user);
        in.at = n >= 0 ? in.at + size_t(n) : in.at - std::min(in.at, size_t(-int64_t(n)));
    }
    static int eof(void *user) {
        auto &in = *static_cast<StbInput *>(user);
        return in.at >= in.bytes->size();
    }
};


// A file for stb_image, its format and header checked.
struct StbFile {
    std::string path, bytes;
    StbFormat format = StbFormat::Unknown;
    StbHeader header;
};
// The file read whole, its format told and its header checked; fails naming the path.
StbFile open_stb(const std::string &path);

}  // namespace neepp::image_check
