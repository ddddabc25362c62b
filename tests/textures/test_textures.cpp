#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "neepp/textures/bitmap_texture.h"
#include "neepp/textures/checkerboard_texture.h"
#include "common/temp_dir.h"

using namespace neepp;

namespace {

SurfaceInteraction at_uv(float u, float v) {
    SurfaceInteraction si;
    si.uv = Vec2(u, v);
    return si;
}

// W x H RGB image whose texel (x, y) is (x, y, 10 + x + 4y): every texel is distinct and identifiable.
Image coords_image(int w, int h) {
    Image img(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            img.at(x, y, 0) = float(x);
            img.at(x, y, 1) = float(y);
            img.at(x, y, 2) = float(10 + x + 4 * y);
        }
    return img;
}

void expect_color(const Color &a, const Color &b, float tol = 1e-6f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

constexpr int W = 4, H = 2;

// Center of texel (x, y) in uv.
SurfaceInteraction center(int x, int y) { return at_uv((x + 0.5f) / W, (y + 0.5f) / H); }

}  // namespace

TEST(BitmapTexture, TexelCentersReturnTexelsAndRowZeroIsTop) {
    BitmapTexture tex(coords_image(W, H));
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) expect_color(tex.eval(center(x, y)), Color(x, y, 10 + x + 4 * y));
    // Small v is the image's first row (the top of the file).
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.3f, 0.25f)).y, 0.f);
}

TEST(BitmapTexture, BilinearBetweenCenters) {
    BitmapTexture tex(coords_image(W, H));
    // Halfway between centers of (1,0) and (2,0), a quarter of the way from row 0 to row 1.
    Color c = tex.eval(at_uv(2.f / W, (0.5f + 0.25f) / H));
    expect_color(c, Color(1.5f, 0.25f, 10 + 1.5f + 4 * 0.25f));
}

TEST(BitmapTexture, WrapModesAtTheBorder) {
    // At u = 0 the bilinear footprint straddles column -1 and column 0.
    auto at_u0 = [](WrapMode m) {
        BitmapOptions o;
        o.wrap = m;
        return BitmapTexture(coords_image(W, H), o).eval(at_uv(0.f, 0.5f / H)).x;
    };
    EXPECT_FLOAT_EQ(at_u0(WrapMode::Repeat), 0.5f * (W - 1));  // average of last and first column
    EXPECT_FLOAT_EQ(at_u0(WrapMode::Clamp), 0.f);
    EXPECT_FLOAT_EQ(at_u0(WrapMode::Mirror), 0.f);

    // Nearest lookups at texel columns -1, -2, W and 2W+1 show each mode's index map.
    auto column = [](WrapMode m, int x) {
        BitmapOptions o;
        o.wrap = m;
        o.filter = FilterType::Nearest;
        return BitmapTexture(coords_image(W, H), o).eval(at_uv((x + 0.5f) / W, 0.25f)).x;
    };
    EXPECT_FLOAT_EQ(column(WrapMode::Repeat, -1), W - 1);
    EXPECT_FLOAT_EQ(column(WrapMode::Repeat, -2), W - 2);
    EXPECT_FLOAT_EQ(column(WrapMode::Repeat, W), 0);
    EXPECT_FLOAT_EQ(column(WrapMode::Mirror, -1), 0);
    EXPECT_FLOAT_EQ(column(WrapMode::Mirror, -2), 1);
    EXPECT_FLOAT_EQ(column(WrapMode::Mirror, -W - 1), W - 1);
    EXPECT_FLOAT_EQ(column(WrapMode::Mirror, W), W - 1);
    EXPECT_FLOAT_EQ(column(WrapMode::Mirror, 2 * W + 1), 1);
    EXPECT_FLOAT_EQ(column(WrapMode::Clamp, -2), 0);
    EXPECT_FLOAT_EQ(column(WrapMode::Clamp, W + 3), W - 1);
}

TEST(BitmapTexture, RepeatedLookupsAtOnePointAgreeWithFreshOnes) {
    // eval keeps its last lookup at each shading point: a second lookup at the same point must give
    // the same value, one at another uv (same object, moved) or of another texture must not get it.
    BitmapTexture a(coords_image(W, H)), b(coords_image(2 * W, 2 * H));
    SurfaceInteraction si = at_uv(0.3f, 0.6f);
    const Color first = a.eval(si);
    expect_color(a.eval(si), first, 0.f);
    expect_color(b.eval(si), b.eval(at_uv(0.3f, 0.6f)), 0.f);
    EXPECT_NE(b.eval(si).x, first.x);
    expect_color(a.eval(si), first, 0.f);
    for (float u : {0.1f, 0.35f, 0.8f, 1.7f, -0.4f}) {
        si.uv = Vec2(u, 0.6f);
        expect_color(a.eval(si), a.eval(at_uv(u, 0.6f)), 0.f);
        EXPECT_NE(a.eval(si).x, first.x) << "stale value at u=" << u;
    }
    // A prefetch leaves the located footprint for the next read: prefetched, then read, at a point, after
    // a prefetch of another texture or uv, with nearest filtering too: always the fresh value.
    BitmapOptions nearest;
    nearest.filter = FilterType::Nearest;
    BitmapTexture n(coords_image(W, H), nearest);
    for (float u : {0.2f, 0.55f, 1.3f}) {
        for (const BitmapTexture *t : {&a, &b, &n}) {
            SurfaceInteraction p = at_uv(u, 0.7f);
            t->prefetch(p);
            expect_color(t->eval(p), t->eval(at_uv(u, 0.7f)), 0.f);
            expect_color(t->eval(p), t->eval(at_uv(u, 0.7f)), 0.f);
            SurfaceInteraction q = at_uv(u, 0.7f);
            a.prefetch(q);
            q.uv = Vec2(u + 0.25f, 0.7f);
            expect_color(t->eval(q), t->eval(at_uv(u + 0.25f, 0.7f)), 0.f);
            SurfaceInteraction r = at_uv(u, 0.7f);
            b.prefetch(r);
            expect_color(t->eval(r), t->eval(at_uv(u, 0.7f)), 0.f);
        }
    }
}

// The memos outlive the textures: one made later, where an earlier one was, reads its own texels at a point
// the earlier one was read at (and a copy, which has the same texels, may share the earlier's lookups).
TEST(BitmapTexture, ALaterTextureAtTheSameAddressFindsNoneOfTheEarliersLookups) {
    const SurfaceInteraction si = at_uv(0.3f, 0.6f);
    Image dark = coords_image(W, H), bright = coords_image(W, H);
    for (float &v : bright.data) v += 100.f;
    for (int round = 0; round < 8; ++round) {
        auto first = std::make_unique<BitmapTexture>(round % 2 ? bright : dark);
        first->prefetch(si);
        const Color before = first->eval(si);
        first.reset();
        auto second = std::make_unique<BitmapTexture>(round % 2 ? dark : bright);
        const Color after = second->eval(si);
        EXPECT_NEAR(std::abs(after.x - before.x), 100.f, 1e-3f) << round;
        const BitmapTexture copy = *second;
        expect_color(copy.eval(si), after, 0.f);
    }
}

TEST(BitmapTexture, NearestHasNoHalfTexelShift) {
    BitmapOptions o;
    o.filter = FilterType::Nearest;
    BitmapTexture tex(coords_image(W, H), o);
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.999f / W, 0.f)).x, 0.f);
    EXPECT_FLOAT_EQ(tex.eval(at_uv(1.001f / W, 0.f)).x, 1.f);
    EXPECT_EQ(tex.eval_1_grad(at_uv(0.3f, 0.3f)).x, 0.f);
}

TEST(BitmapTexture, SrgbDataIsLinearizedUnlessRaw) {
    Image img(2, 2, 3);
    for (float &v : img.data) v = 128.f * (1.f / 255.f);
    img.srgb_encoded = true;
    EXPECT_FLOAT_EQ(BitmapTexture(img).eval(at_uv(0.3f, 0.6f)).y, srgb_to_linear(128.f / 255.f));
    BitmapOptions raw;
    raw.raw = true;
    EXPECT_FLOAT_EQ(BitmapTexture(img, raw).eval(at_uv(0.3f, 0.6f)).y, 128.f / 255.f);
}

TEST(BitmapTexture, LoadsFileAndLinearizesOnce) {
    Image img(2, 1, 3);
    img.data = {0.5f, 0.5f, 0.5f, 0.05f, 0.05f, 0.05f};
    const std::string path = (std::filesystem::temp_directory_path() / "neepp_test_bitmap.png").string();
    write_png_srgb(path, img);
    auto tex = BitmapTexture::load(path);
    const float code = std::round(linear_to_srgb(0.5f) * 255.f);
    EXPECT_FLOAT_EQ(tex->eval(at_uv(0.25f, 0.5f)).x, srgb_to_linear(code / 255.f));
    EXPECT_NEAR(tex->eval(at_uv(0.25f, 0.5f)).x, 0.5f, 3e-3f);
    std::filesystem::remove(path);
    EXPECT_THROW(BitmapTexture::load(path), std::runtime_error);
}

TEST(BitmapTexture, EightBitFilesReadAsCodesEqualTheFloatPath) {
    // load() keeps an 8-bit file's codes without a float copy; the texture must be the one built from
    // read_image's floats: same texels, means and channel count, with and without alpha, raw or not.
    const neepp::testing::TempDir tmp;
    for (int channels : {1, 2, 3, 4}) {
        Image img(5, 3, channels);
        for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float((i * 37) % 101) / 100.f;
        const std::string path = (tmp.dir / "bytes.png").string();
        write_png_srgb(path, img);
        ASSERT_TRUE(read_image_bytes(path).has_value());
        for (bool raw : {false, true}) {
            SCOPED_TRACE(::testing::Message() << channels << " channels, raw " << raw);
            BitmapOptions options;
            options.raw = raw;
            auto from_codes = BitmapTexture::load(path, options);
            BitmapTexture from_floats(read_image(path), options);
            EXPECT_EQ(from_codes->channels(), from_floats.channels());
            EXPECT_EQ(from_codes->mean().x, from_floats.mean().x);
            EXPECT_EQ(from_codes->mean_rgb().z, from_floats.mean_rgb().z);
            for (float u : {0.05f, 0.3f, 0.71f})
                for (float v : {0.1f, 0.5f, 0.93f}) {
                    const Color a = from_codes->eval(at_uv(u, v)), b = from_floats.eval(at_uv(u, v));
                    EXPECT_EQ(a.x, b.x);
                    EXPECT_EQ(a.y, b.y);
                    EXPECT_EQ(a.z, b.z);
                }
        }
        std::filesystem::remove(path);
    }
    // Files read as floats have no 8-bit reading.
    const std::string exr = (tmp.dir / "bytes.exr").string();
    write_exr(exr, coords_image(2, 2));
    EXPECT_FALSE(read_image_bytes(exr).has_value());
    std::filesystem::remove(exr);
    EXPECT_THROW(read_image_bytes(exr), std::runtime_error);
}

TEST(BitmapTexture, Eval1IsLuminanceOrTheSingleChannel) {
    BitmapTexture rgb(coords_image(W, H));
    EXPECT_NEAR(rgb.eval_1(center(2, 1)), luminance(Color(2, 1, 16)), 1e-5f);

    Image gray(2, 2, 2);  // gray + alpha: alpha is dropped, one channel remains
    gray.data = {0.1f, 1.f, 0.2f, 1.f, 0.3f, 0.f, 0.4f, 0.f};
    BitmapTexture mono(gray);
    EXPECT_EQ(mono.channels(), 1);
    EXPECT_FLOAT_EQ(mono.eval_1(at_uv(0.75f, 0.25f)), 0.2f);
    expect_color(mono.eval(at_uv(0.75f, 0.25f)), Color(0.2f));
    EXPECT_FLOAT_EQ(mono.mean().x, 0.25f);
}

TEST(BitmapTexture, Eval1GradMatchesFiniteDifferences) {
    Transform scale = Transform::scale(Vec3(2.f, 3.f, 1.f));
    for (const Transform &t : {Transform(), scale}) {
        BitmapOptions o;
        o.to_uv = t;
        BitmapTexture tex(coords_image(W, H), o);
        // A point well inside one bilinear cell (in texture space), where eval_1 is bilinear.
        const Vec2 uv = t.matrix.m[0][0] == 1.f ? Vec2(0.4f, 0.55f) : Vec2(0.2f, 0.55f / 3.f);
        const float h = 1e-3f;
        const Vec2 g = tex.eval_1_grad(at_uv(uv.x, uv.y));
        const float fu = (tex.eval_1(at_uv(uv.x + h, uv.y)) - tex.eval_1(at_uv(uv.x - h, uv.y))) / (2 * h);
        const float fv = (tex.eval_1(at_uv(uv.x, uv.y + h)) - tex.eval_1(at_uv(uv.x, uv.y - h))) / (2 * h);
        EXPECT_NEAR(g.x, fu, 2e-2f);
        EXPECT_NEAR(g.y, fv, 2e-2f);
        EXPECT_GT(std::abs(g.x), 1.f);
    }
}

TEST(BitmapTexture, MeanIsMeanLuminanceAsGray) {
    BitmapTexture tex(coords_image(W, H));
    // Channel means: x = 1.5, y = 0.5, z = 10 + 1.5 + 2 = 13.5.
    expect_color(tex.mean_rgb(), Color(1.5f, 0.5f, 13.5f), 1e-5f);
    const float lum = luminance(Color(1.5f, 0.5f, 13.5f));
    expect_color(tex.mean(), Color(lum), 1e-5f);
}

TEST(BitmapTexture, ToUvUsesTranslationColumnLikeMitsuba) {
    UvTransform t(Transform::translate(Vec3(0.5f, 0.25f, 7.f)) * Transform::scale(Vec3(2.f, 3.f, 5.f)));
    Vec2 p = t.apply(Vec2(1.f, 1.f));
    EXPECT_FLOAT_EQ(p.x, 2.5f);
    EXPECT_FLOAT_EQ(p.y, 3.25f);

    BitmapOptions o;
    o.to_uv = Transform::translate(Vec3(1.f / W, 0.f, 0.f));  // shift by one texel
    BitmapTexture tex(coords_image(W, H), o);
    expect_color(tex.eval(center(0, 1)), Color(1, 1, 15));
}

TEST(BitmapTexture, RejectsUnknownOptions) {
    EXPECT_EQ(parse_filter_type("nearest"), FilterType::Nearest);
    EXPECT_EQ(parse_wrap_mode("mirror"), WrapMode::Mirror);
    EXPECT_THROW(parse_filter_type("trilinear"), std::runtime_error);
    EXPECT_THROW(parse_wrap_mode("wrap"), std::runtime_error);
}

TEST(CheckerboardTexture, MitsubaPatternAndDefaults) {
    CheckerboardTexture tex;
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.25f, 0.25f)).x, 0.4f);   // cell at the origin: color0
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.75f, 0.25f)).x, 0.2f);
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.25f, 0.75f)).x, 0.2f);
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.75f, 0.75f)).x, 0.4f);
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.5f, 0.25f)).x, 0.4f);    // frac == 0.5 is not > 0.5
    EXPECT_FLOAT_EQ(tex.eval(at_uv(-0.25f, 0.25f)).x, 0.2f);  // frac(-0.25) = 0.75
    EXPECT_FLOAT_EQ(tex.eval(at_uv(1.25f, 3.25f)).x, 0.4f);   // period 1 in u and v
    expect_color(tex.mean(), Color(0.3f));
}

TEST(CheckerboardTexture, Eval1UsesMitsubasSwappedAssignment) {
    CheckerboardTexture tex(constant_texture(Color(1.f)), constant_texture(Color(0.f)));
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.25f, 0.25f)).x, 1.f);
    EXPECT_FLOAT_EQ(tex.eval_1(at_uv(0.25f, 0.25f)), 0.f);
    EXPECT_FLOAT_EQ(tex.eval_1(at_uv(0.75f, 0.25f)), 1.f);
}

TEST(CheckerboardTexture, ToUvScalesThePattern) {
    CheckerboardTexture tex(constant_texture(1.f), constant_texture(0.f), Transform::scale(Vec3(2.f, 2.f, 1.f)));
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.3f, 0.1f)).x, 0.f);  // (0.6, 0.2)
    EXPECT_FLOAT_EQ(tex.eval(at_uv(0.3f, 0.3f)).x, 1.f);  // (0.6, 0.6)
}
