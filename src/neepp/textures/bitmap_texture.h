// Mitsuba 3's `bitmap` texture: an image looked up by uv with bilinear or nearest filtering.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "neepp/base/texture.h"
#include "neepp/io/image.h"
#include "neepp/math/transform.h"

namespace neepp {

// Mitsuba's `to_uv`: a 2D affine map of uv. A 4x4 transform is reduced as Mitsuba's
// Transform4f::extract() does: the upper-left 2x2 block plus the translation column (entries 0,3 and 1,3);
// z and the projective row are ignored. Shared by the bitmap and checkerboard textures.
struct UvTransform {
    float m[2][3] = {{1, 0, 0}, {0, 1, 0}};

    UvTransform() = default;
    explicit UvTransform(const Transform &t);
    // Same fused multiply-add order as Mitsuba's affine transform of a Point2f.
    Vec2 apply(Vec2 uv) const;
};

enum class FilterType { Bilinear, Nearest };
enum class WrapMode { Repeat, Mirror, Clamp };

// Parse Mitsuba's `filter_type` / `wrap_mode` strings; throw std::runtime_error on anything else.
FilterType parse_filter_type(std::string_view s);
WrapMode parse_wrap_mode(std::string_view s);

struct BitmapOptions {
    FilterType filter = FilterType::Bilinear;
    WrapMode wrap = WrapMode::Repeat;
    bool raw = false;  // true: keep sRGB-encoded values as they are (normal maps, masks stored linearly)
    Transform to_uv;
};

// Matches Mitsuba 3.9 (src/textures/bitmap.cpp + Dr.Jit's texture lookup):
//  * uv (0,0) is the top-left corner of the image (row 0 = first row of the file); texel (i, j) has its
//    center at ((i+0.5)/W, (j+0.5)/H). No v flip here: mesh loaders flip v like Mitsuba's OBJ loader.
//  * Alpha is dropped; 1-channel (and gray+alpha) images stay single-channel.
//  * Unless `raw`, sRGB-encoded data is linearized once per texel at load (Mitsuba decodes each 8-bit texel
//    before interpolating, which gives the same values).
//  * eval_1 is the interpolated value for 1 channel, else the luminance of the interpolated RGB.
//  * mean() is Mitsuba's scalar mean (mean texel luminance, or mean value), returned as a gray Color so
//    that averaging its channels or taking its luminance both give Mitsuba's number; mean_rgb() is the
//    per-channel mean.
class BitmapTexture final : public Texture {
public:
    explicit BitmapTexture(const Image &image, const BitmapOptions &options = {});
    // An 8-bit file's codes (sRGB-encoded, as Mitsuba reads 8-bit files), kept as they are.
    explicit BitmapTexture(ImageBytes image, const BitmapOptions &options = {});
    // Reads `filename` (8-bit files with read_image_bytes, without a float copy; others with read_image);
    // throws std::runtime_error naming the path on failure.
    static std::shared_ptr<BitmapTexture> load(const std::string &filename, const BitmapOptions &options = {});

    Color eval(const SurfaceInteraction &si) const override;
    float eval_1(const SurfaceInteraction &si) const override;
    // d eval_1 / d(u, v) of the bilinear interpolant (zero for nearest filtering), as Mitsuba computes it:
    // the luminances of the four fetched texels are differentiated, and the result is scaled per axis by
    // the resolution after the to_uv transpose.
    Vec2 eval_1_grad(const SurfaceInteraction &si) const override;
    Color mean() const override { return Color(mean_); }
    void prefetch(const SurfaceInteraction &si) const override;
    Color mean_rgb() const { return mean_rgb_; }

    int width() const { return width_; }
    int height() const { return height_; }
    int channels() const { return channels_; }  // 1 or 3
    const BitmapOptions &options() const { return options_; }

private:
    struct Lookup;  // texel indices and bilinear weights of one query
    struct Memo;    // a lookup kept for the next read at the same point (bitmap_texture.cpp)
    static Memo &memo_at(const SurfaceInteraction &si);
    Lookup locate(Vec2 uv) const;
    Color texel(int x, int y) const;  // already wrapped coordinates
    Color interpolate(Vec2 uv) const;
    Color blend(const Lookup &l) const;  // bilinear blend of a located footprint
    // With codes_ filled: the decode table (linear unless raw, srgb says whether codes are sRGB) and means.
    void finish_codes(bool srgb);
    // mean_ and mean_rgb_ from value(i), the linear value of channel i % channels_ of texel i / channels_.
    template <typename Value>
    void compute_means(Value value);

    int width_ = 0, height_ = 0, channels_ = 3;
    std::vector<float> texels_;     // float data (HDR images), or empty when codes_ is used
    std::vector<uint8_t> codes_;    // 8-bit data, decoded through lut_
    std::array<float, 256> lut_{};  // linear (unless raw), row-major, top row first
    BitmapOptions options_;
    UvTransform to_uv_;
    float mean_ = 0;
    Color mean_rgb_;
    // Names this texture in the memos, which outlive it: a texture made later at the same address must not
    // find this one's lookups.
    uint64_t memo_key_ = next_memo_key();
    static uint64_t next_memo_key();
};

}  // namespace neepp
