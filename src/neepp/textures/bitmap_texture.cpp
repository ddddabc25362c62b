#include "neepp/textures/bitmap_texture.h"

#include <atomic>
#include <array>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace neepp {

UvTransform::UvTransform(const Transform &t) {
    const auto &a = t.matrix.m;
    m[0][0] = a[0][0], m[0][1] = a[0][1], m[0][2] = a[0][3];
    m[1][0] = a[1][0], m[1][1] = a[1][1], m[1][2] = a[1][3];
}

Vec2 UvTransform::apply(Vec2 uv) const {
    return {std::fma(m[0][1], uv.y, std::fma(m[0][0], uv.x, m[0][2])),
            std::fma(m[1][1], uv.y, std::fma(m[1][0], uv.x, m[1][2]))};
}

FilterType parse_filter_type(std::string_view s) {
    if (s == "bilinear") return FilterType::Bilinear;
    if (s == "nearest") return FilterType::Nearest;
    throw std::runtime_error(fmt::format("invalid filter_type \"{}\": must be \"bilinear\" or \"nearest\"", s));
}

WrapMode parse_wrap_mode(std::string_view s) {
    if (s == "repeat") return WrapMode::Repeat;
    if (s == "mirror") return WrapMode::Mirror;
    if (s == "clamp") return WrapMode::Clamp;
    throw std::runtime_error(fmt::format("invalid wrap_mode \"{}\": must be \"repeat\", \"mirror\" or \"clamp\"", s));
}

namespace {

// Dr.Jit's integer wrap (texture_impl.h tex_wrap), including its Euclidean modulo and mirror parity rule.
int wrap(int pos, int res, WrapMode mode) {
    if (mode == WrapMode::Clamp) return std::clamp(pos, 0, res - 1);
    if (unsigned(pos) < unsigned(res)) return pos;  // inside: every mode is the identity (no division)
    const int div = (pos < 0 ? pos + 1 : pos) / res;
    int mod = pos - div * res;
    if (mod < 0) mod += res;
    if (mode == WrapMode::Mirror && !(((div & 1) == 0) ^ (pos < 0))) mod = res - 1 - mod;
    return mod;
}

// sRGB decode of a normalized value. 8-bit codes (the common case) hit a table instead of calling pow
// for every texel of a large texture; the result is identical.
float decode_srgb(float v) {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[i] = srgb_to_linear(float(i) * (1.f / 255.f));
        return t;
    }();
    const float code = std::round(v * 255.f);
    if (code >= 0.f && code <= 255.f && float(code) * (1.f / 255.f) == v) return table[int(code)];
    return srgb_to_linear(v);
}

}  // namespace

struct BitmapTexture::Lookup {
    int x0, x1, y0, y1;     // wrapped texel coordinates of the 2x2 footprint
    float wx0, wx1, wy0, wy1;  // bilinear weights toward the lower / upper texel
};

namespace {

// out = convert(v) for the colour channels of src (src_channels per texel); alpha, the last source
// channel, is dropped, as in Mitsuba.
template <typename Out, typename Src, typename Convert>
void copy_color_channels(std::vector<Out> &out, const std::vector<Src> &src, int src_channels, int channels,
                         Convert convert) {
    const size_t pixels = src.size() / size_t(src_channels);
    out.resize(pixels * channels);
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < channels; ++c) out[i * channels + c] = convert(src[i * src_channels + c]);
}

}  // namespace

template <typename Value>
void BitmapTexture::compute_means(Value value) {
    const size_t pixels = size_t(width_) * height_;
    double sum = 0, sum_rgb[3] = {0, 0, 0};
    for (size_t i = 0; i < pixels; ++i) {
        float t[3];
        for (int c = 0; c < channels_; ++c) sum_rgb[c] += t[c] = value(i * channels_ + c);
        sum += channels_ == 1 ? t[0] : luminance(Color(t[0], t[1], t[2]));
    }
    mean_ = float(sum / double(pixels));
    mean_rgb_ = channels_ == 1 ? Color(mean_)
                               : Color(float(sum_rgb[0] / pixels), float(sum_rgb[1] / pixels),
                                       float(sum_rgb[2] / pixels));
}

BitmapTexture::BitmapTexture(const Image &image, const BitmapOptions &options)
    : width_(image.width), height_(image.height), channels_(image.color_channels()), options_(options),
      to_uv_(options.to_uv) {
    if (width_ <= 0 || height_ <= 0 || image.data.size() != size_t(width_) * height_ * image.channels)
        throw std::runtime_error(fmt::format("bitmap texture: invalid image ({}x{}, {} channels)", width_,
                                             height_, image.channels));
    const size_t pixels = size_t(width_) * height_;
    // 8-bit images stay 8-bit, decoded through a 256-entry table on lookup: a quarter of the memory
    // and cache traffic of floats (texture fetches are cache misses on large maps), same values.
    bool all_codes = true;
    for (size_t i = 0; i < pixels && all_codes; ++i)
        for (int c = 0; c < channels_; ++c) {
            // nearbyint, not round: one instruction instead of a libm call per texel channel (a large
            // share of loading). Both give the same integer wherever v is a code (v * 255 is then an
            // integer to within rounding); elsewhere the check below fails either way.
            float v = image.data[i * image.channels + c], code = std::nearbyint(v * 255.f);
            if (!(code >= 0.f && code <= 255.f && code * (1.f / 255.f) == v)) { all_codes = false; break; }
        }
    if (all_codes) {
        copy_color_channels(codes_, image.data, image.channels, channels_,
                            [](float v) { return uint8_t(std::nearbyint(v * 255.f)); });
        finish_codes(image.srgb_encoded);
        return;
    }
    const bool linearize = image.srgb_encoded && !options.raw;
    copy_color_channels(texels_, image.data, image.channels, channels_,
                        [&](float v) { return linearize ? decode_srgb(v) : v; });
    compute_means([&](size_t i) { return texels_[i]; });
}

BitmapTexture::BitmapTexture(ImageBytes image, const BitmapOptions &options)
    : width_(image.width), height_(image.height), channels_(image.color_channels()), options_(options),
      to_uv_(options.to_uv) {
    if (width_ <= 0 || height_ <= 0 || image.channels < 1 || image.channels > 4 ||
        image.data.size() != size_t(width_) * height_ * image.channels)
        throw std::runtime_error(fmt::format("bitmap texture: invalid image ({}x{}, {} channels)", width_,
                                             height_, image.channels));
    if (channels_ == image.channels) codes_ = std::move(image.data);
    else copy_color_channels(codes_, image.data, image.channels, channels_, [](uint8_t v) { return v; });
    finish_codes(true);
}

void BitmapTexture::finish_codes(bool srgb) {
    const bool linearize = srgb && !options_.raw;
    for (int i = 0; i < 256; ++i) lut_[i] = linearize ? decode_srgb(float(i) * (1.f / 255.f)) : float(i) * (1.f / 255.f);
    compute_means([&](size_t i) { return lut_[codes_[i]]; });
}

std::shared_ptr<BitmapTexture> BitmapTexture::load(const std::string &filename, const BitmapOptions &options) {
    if (std::optional<ImageBytes> bytes = read_image_bytes(filename))
        return std::make_shared<BitmapTexture>(std::move(*bytes), options);
    return std::make_shared<BitmapTexture>(read_image(filename), options);
}

// Always inlined: the bilinear blend fetches four texels per lookup.
[[gnu::always_inline]] inline Color BitmapTexture::texel(int x, int y) const {
    size_t i = (size_t(y) * width_ + x) * channels_;
    if (!codes_.empty()) {
        const uint8_t *t = &codes_[i];
        return channels_ == 1 ? Color(lut_[t[0]]) : Color(lut_[t[0]], lut_[t[1]], lut_[t[2]]);
    }
    const float *t = &texels_[i];
    return channels_ == 1 ? Color(t[0]) : Color(t[0], t[1], t[2]);
}

// Dr.Jit's linear lookup: texel centers at (i + 0.5) / res, so the footprint starts at floor(u*res - 0.5).
BitmapTexture::Lookup BitmapTexture::locate(Vec2 uv) const {
    const float px = std::fma(uv.x, float(width_), -0.5f), py = std::fma(uv.y, float(height_), -0.5f);
    const float fx = std::floor(px), fy = std::floor(py);
    const int ix = int(fx), iy = int(fy);
    Lookup l;
    l.wx1 = px - fx, l.wx0 = 1.f - l.wx1;
    l.wy1 = py - fy, l.wy0 = 1.f - l.wy1;
    l.x0 = wrap(ix, width_, options_.wrap), l.y0 = wrap(iy, height_, options_.wrap);
    if (options_.wrap == WrapMode::Repeat) {
        // The upper neighbour wraps with the lower one: a modulo is not needed twice (tiled textures' uv
        // lie outside [0, 1), where wrap divides).
        l.x1 = l.x0 + 1 == width_ ? 0 : l.x0 + 1;
        l.y1 = l.y0 + 1 == height_ ? 0 : l.y0 + 1;
    } else {
        l.x1 = wrap(ix + 1, width_, options_.wrap), l.y1 = wrap(iy + 1, height_, options_.wrap);
    }
    return l;
}

Color BitmapTexture::interpolate(Vec2 uv) const {
    if (options_.filter == FilterType::Nearest) {
        // Nearest: no half-texel shift, the texel containing u*res.
        const int x = int(std::floor(uv.x * float(width_))), y = int(std::floor(uv.y * float(height_)));
        return texel(wrap(x, width_, options_.wrap), wrap(y, height_, options_.wrap));
    }
    return blend(locate(uv));
}

Color BitmapTexture::blend(const Lookup &l) const {
    // Same corner order and fused accumulation as Dr.Jit, so results agree to the last bit.
    const Color c[4] = {texel(l.x0, l.y0), texel(l.x1, l.y0), texel(l.x0, l.y1), texel(l.x1, l.y1)};
    const float w[4] = {l.wx0 * l.wy0, l.wx1 * l.wy0, l.wx0 * l.wy1, l.wx1 * l.wy1};
    Color out(0.f);
    for (int k = 0; k < 4; ++k)
        for (int ch = 0; ch < 3; ++ch) out[ch] = std::fma(c[k][ch], w[k], out[ch]);
    return out;
}

// The last lookup made at a shading point: a BSDF reads its textures when next event estimation
// evaluates it and again when it is sampled, and the second read is then a copy; the prefetch before both
// (the fast form's) leaves the texel footprint it located, so the first read does not locate it again.
// Keyed by the texture and the uv, on which alone a bitmap's value depends: a memo found is what a new
// lookup would give, to the bit, so it never needs resetting and cannot return a stale value.
struct BitmapTexture::Memo {
    uint64_t texture;  // the texture's memo key; 0: empty
    Vec2 uv;
    bool has_value;  // else only located (by a prefetch): the footprint below
    Color value;
    Lookup footprint;
    bool holds(uint64_t key, Vec2 at) const { return texture == key && uv.x == at.x && uv.y == at.y; }
};

uint64_t BitmapTexture::next_memo_key() {
    static std::atomic<uint64_t> next{1};
    return next.fetch_add(1, std::memory_order_relaxed);
}

// Each thread's memos, one slot per shading point in flight (chosen by the SurfaceInteraction's address):
// the fast form prefetches a batch of paths' textures before it reads any, so one memo would hold only
// the last path's. Two points that share a slot cost a lookup, never a wrong value.
BitmapTexture::Memo &BitmapTexture::memo_at(const SurfaceInteraction &si) {
    constexpr int kSlotBits = 6;
    thread_local Memo memos[1 << kSlotBits];  // zero-initialized: empty
    const uint64_t key = reinterpret_cast<uintptr_t>(&si) * 0x9E3779B97F4A7C15ull;
    return memos[key >> (64 - kSlotBits)];
}

void BitmapTexture::prefetch(const SurfaceInteraction &si) const {
    Memo &memo = memo_at(si);
    if (memo.holds(memo_key_, si.uv)) return;  // located or read already
    const Lookup l = locate(to_uv_.apply(si.uv));  // both rows of the bilinear footprint (nearest: a subset)
    for (int y : {l.y0, l.y1}) {
        const size_t i = (size_t(y) * width_ + l.x0) * channels_;
        if (!codes_.empty()) __builtin_prefetch(&codes_[i]);
        else __builtin_prefetch(&texels_[i]);
    }
    memo = {memo_key_, si.uv, false, Color(0.f), l};
}

Color BitmapTexture::eval(const SurfaceInteraction &si) const {
    Memo &memo = memo_at(si);
    if (memo.holds(memo_key_, si.uv)) {
        if (memo.has_value) return memo.value;
        if (options_.filter == FilterType::Bilinear) {
            memo.value = blend(memo.footprint);
            memo.has_value = true;
            return memo.value;
        }
    }
    const Color c = interpolate(to_uv_.apply(si.uv));
    memo = {memo_key_, si.uv, true, c, {}};
    return c;
}

float BitmapTexture::eval_1(const SurfaceInteraction &si) const {
    const Color c = interpolate(to_uv_.apply(si.uv));
    return channels_ == 1 ? c.x : luminance(c);
}

Vec2 BitmapTexture::eval_1_grad(const SurfaceInteraction &si) const {
    if (options_.filter == FilterType::Nearest) return {0.f, 0.f};  // piecewise constant
    const Lookup l = locate(to_uv_.apply(si.uv));
    auto value = [&](int x, int y) {
        const Color c = texel(x, y);
        return channels_ == 1 ? c.x : luminance(c);
    };
    const float f00 = value(l.x0, l.y0), f10 = value(l.x1, l.y0), f01 = value(l.x0, l.y1),
                f11 = value(l.x1, l.y1);
    // Partials w.r.t. texel coordinates, then chain rule through to_uv (transpose multiply).
    const float dx = std::fma(l.wy0, f10 - f00, l.wy1 * (f11 - f01));
    const float dy = std::fma(l.wx0, f01 - f00, l.wx1 * (f11 - f10));
    const auto &m = to_uv_.m;
    const float du = m[0][0] * dx + m[1][0] * dy, dv = m[0][1] * dx + m[1][1] * dy;
    // Mitsuba scales by the resolution after the transpose multiply (exact for diagonal to_uv).
    return {float(width_) * du, float(height_) * dv};
}

}  // namespace neepp
