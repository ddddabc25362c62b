// In-memory float RGB(A) images and reading/writing them (OpenEXR for HDR, PNG/JPEG through stb_image).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>
#include "neepp/math/vec.h"

namespace neepp {

struct Image {
    // channels: 1 (Y), 2 (Y + alpha, from gray+alpha files), 3 (RGB) or 4 (RGBA); alpha is always last.
    int width = 0, height = 0, channels = 3;
    std::vector<float> data;                   // row-major, top row first, interleaved channels
    bool srgb_encoded = false;                 // true for 8/16-bit files whose values are sRGB-encoded

    Image() = default;
    Image(int w, int h, int c) : width(w), height(h), channels(c), data(size_t(w) * h * c, 0.f) {}
    float &at(int x, int y, int c) { return data[(size_t(y) * width + x) * channels + c]; }
    float at(int x, int y, int c) const { return data[(size_t(y) * width + x) * channels + c]; }
    Color rgb(int x, int y) const {
        const float *p = &data[(size_t(y) * width + x) * channels];
        return channels >= 3 ? Color(p[0], p[1], p[2]) : Color(p[0]);
    }
    bool has_alpha() const { return channels == 2 || channels == 4; }
    int color_channels() const { return has_alpha() ? channels - 1 : channels; }  // 1 or 3
};

// The largest side of an image read or rendered (a film's, an OpenEXR file's data window): refused beyond.
constexpr int kMaxImageSide = 1 << 15;

// Reads EXR (linear; half or float; R,G,B[,A] or Y[,A] channels), PNG, JPEG, HDR, TGA, BMP and binary PNM
// (P5, P6). The format is detected from the file's contents, not its name; other formats stb_image knows
// (GIF, PSD, PIC) are refused. A file shorter than its header says (truncated), or whose header asks for
// more pixels than its bytes can hold, is refused before its pixels are allocated, never read as zeros.
// Integer formats come back normalized to [0,1] (byte * (1/255), as Dr.Jit's texture does) with
// srgb_encoded = true, as Mitsuba marks them (16-bit PNG included); the caller decides whether to
// linearize (Mitsuba's `raw` flag). Alpha is kept.
// Throws std::runtime_error naming the path on any failure.
Image read_image(const std::string &path);

// An 8-bit file's codes as stored (sRGB-encoded, alpha last), for readers that keep 8-bit data (bitmap
// textures) and so need no float copy of a large image.
struct ImageBytes {
    int width = 0, height = 0, channels = 3;
    std::vector<uint8_t> data;  // row-major, top row first, interleaved channels
    int color_channels() const { return channels == 2 || channels == 4 ? channels - 1 : channels; }  // 1 or 3
};
// JPEG and 8-bit PNG, TGA, BMP, PNM as their codes; std::nullopt for the files read_image reads as floats
// (OpenEXR, HDR, 16-bit). Throws as read_image does.
std::optional<ImageBytes> read_image_bytes(const std::string &path);

// Writes the image to OpenEXR (half or float; channels named Y, YA, RGB or RGBA). Throws on failure.
// Both writers replace the file atomically (see atomic_file.h): never a half-written image.
void write_exr(const std::string &path, const Image &img, bool half = false);
// The channel names of an image of 1 to 4 channels, alpha last (Y, YA, RGB, RGBA), as write_exr and the
// tev display name them; empty for another count.
std::vector<std::string> channel_names(int channels);
// Writes an 8-bit sRGB PNG after exposure scaling and clamping (no other tonemapping). Alpha, if
// present, is written linearly and unscaled. Throws on failure.
void write_png_srgb(const std::string &path, const Image &img, float exposure = 1.f);

// The exact piecewise sRGB transfer functions (IEC 61966-2-1), evaluated in double precision.
float srgb_to_linear(float v);
float linear_to_srgb(float v);

}  // namespace neepp
