// The film: reconstruction filters and filter-weighted accumulation (pixel = Σ w·L / Σ w).
#include <gtest/gtest.h>
#include <array>
#include <tuple>
#include "neepp/render/film.h"
#include "neepp/sampling/rng.h"

using namespace neepp;

TEST(ReconstructionFilter, ProfilesAndSupport) {
    ReconstructionFilter box("box", 0.5f, 0.5f), tent("tent", 1.f, 0.5f), gauss("gaussian", 2.f, 0.5f);
    EXPECT_EQ(box.eval(0.49f), 1.f);
    EXPECT_EQ(box.eval(0.51f), 0.f);
    EXPECT_FLOAT_EQ(tent.eval(0.f), 1.f);
    EXPECT_FLOAT_EQ(tent.eval(0.25f), 0.75f);
    EXPECT_EQ(tent.eval(1.0f), 0.f);
    EXPECT_GT(gauss.eval(0.f), gauss.eval(0.5f));
    EXPECT_NEAR(gauss.eval(2.f), 0.f, 1e-6f);  // shifted to reach zero at the radius, as Mitsuba's
    EXPECT_THROW(ReconstructionFilter("lanczos", 1.f, 0.5f), std::invalid_argument);
    EXPECT_THROW(ReconstructionFilter("tent", 0.f, 0.5f), std::invalid_argument);
}

// Whatever the filter, a constant radiance must resolve to exactly that constant everywhere, including
// the image border (the weights normalize per pixel).
TEST(ImageBlock, ConstantRadianceResolvesToTheConstant) {
    for (const char *name : {"box", "tent", "gaussian"}) {
        ReconstructionFilter f(name, std::string(name) == "box" ? 0.5f : std::string(name) == "tent" ? 1.f : 2.f, 0.5f);
        ImageBlock film(0, 0, 7, 5, &f);
        PCG32 rng(3, 5);
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 7; ++x)
                for (int s = 0; s < 16; ++s) {
                    Vec2 j = rng.next_2d();
                    film.put(float(x) + j.x, float(y) + j.y, Color(0.25f, 0.5f, 2.f));
                }
        Image img = film.resolve();
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 7; ++x) {
                EXPECT_NEAR(img.at(x, y, 0), 0.25f, 1e-5f) << name;
                EXPECT_NEAR(img.at(x, y, 2), 2.f, 1e-5f) << name;
            }
    }
}

// Splitting the image into tiles with borders and merging them gives the same image as one block.
TEST(ImageBlock, TilesWithBordersMergeToTheWholeImage) {
    ReconstructionFilter tent("tent", 1.f, 0.5f);
    ImageBlock whole(0, 0, 8, 6, &tent), merged(0, 0, 8, 6, &tent);
    PCG32 rng(1, 2);
    std::vector<std::tuple<float, float, Color>> samples;
    for (int k = 0; k < 2000; ++k) {
        Vec2 p = rng.next_2d();
        samples.emplace_back(p.x * 8, p.y * 6, Color(rng.next_float(), rng.next_float(), rng.next_float()));
    }
    for (auto &[x, y, L] : samples) whole.put(x, y, L);
    for (int ty = 0; ty < 6; ty += 3)
        for (int tx = 0; tx < 8; tx += 4) {
            ImageBlock tile(tx - 1, ty - 1, 4 + 2, 3 + 2, &tent);
            for (auto &[x, y, L] : samples)
                if (x >= tx && x < tx + 4 && y >= ty && y < ty + 3) tile.put(x, y, L);
            merged.merge(tile);
        }
    Image a = whole.resolve(), b = merged.resolve();
    for (size_t i = 0; i < a.data.size(); ++i) EXPECT_NEAR(a.data[i], b.data[i], 1e-5f);
}

// Each sample adds w_x·w_y·L and w_x·w_y to every pixel whose centre lies within the filter's radius, and
// nothing elsewhere: two samples of different radiance, written out by hand against the filter profile.
TEST(ImageBlock, PixelsHoldTheFilterWeightedMeanOfTheirSamples) {
    for (const char *name : {"tent", "gaussian"}) {
        const float radius = std::string(name) == "tent" ? 1.f : 2.f;
        ReconstructionFilter f(name, radius, 0.5f);
        ImageBlock film(0, 0, 7, 6, &f);
        const std::array<std::tuple<float, float, Color>, 2> samples = {
            std::tuple{2.3f, 3.1f, Color(1.f, 2.f, 3.f)}, std::tuple{3.7f, 2.6f, Color(4.f, 0.f, 0.5f)}};
        for (auto &[x, y, L] : samples) film.put(x, y, L);
        Image img = film.resolve();
        int lit = 0;
        for (int py = 0; py < 6; ++py)
            for (int px = 0; px < 7; ++px) {
                double sum[3] = {0, 0, 0}, weight = 0;
                for (auto &[x, y, L] : samples) {
                    const float dx = float(px) + 0.5f - x, dy = float(py) + 0.5f - y;
                    if (std::abs(dx) > radius || std::abs(dy) > radius) continue;
                    const double w = double(f.eval(dx)) * f.eval(dy);
                    for (int c = 0; c < 3; ++c) sum[c] += w * L[c];
                    weight += w;
                }
                lit += weight > 0;
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(img.at(px, py, c), weight > 0 ? sum[c] / weight : 0.0, 1e-6) << name << " " << px << "," << py;
            }
        EXPECT_GT(lit, 4) << name;
    }
}

// A box filter's pixels are half-open, [i, i + 1): a splat exactly on a pixel boundary adds its value
// once, to the pixel on its right (a splat film is not normalized by weights, so counting it in both
// pixels would add its energy twice: the light tracer's point lights once did).
TEST(SplatFilm, ABoxSplatOnAPixelBoundaryCountsOnce) {
    ReconstructionFilter box("box", 0.5f, 0.5f);
    SplatFilm film(4, 3, &box);
    ASSERT_TRUE(film.add(2.0f, 1.0f, Color(1.f)));
    const Image img = film.resolve(1.0);
    double sum = 0;
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x) {
            const float v = img.data[3 * (size_t(y) * 4 + x)];
            sum += v;
            EXPECT_EQ(v, x == 2 && y == 1 ? 1.f : 0.f) << "pixel " << x << "," << y;
        }
    EXPECT_DOUBLE_EQ(sum, 1.0);
}
