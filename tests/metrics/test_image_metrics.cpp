#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "neepp/metrics/image_metrics.h"

using namespace neepp;

namespace {

// I = [(1,2,3), (0,0,0)], R = [(1,1,1), (0.1,0,0.2)]: differences 0,1,2 and -0.1,0,-0.2.
Image rendered() {
    Image img(2, 1, 3);
    img.data = {1, 2, 3, 0, 0, 0};
    return img;
}
Image reference() {
    Image img(2, 1, 3);
    img.data = {1, 1, 1, 0.1f, 0, 0.2f};
    return img;
}

}  // namespace

TEST(ImageMetrics, HandComputedValues) {
    const Image i = rendered(), r = reference();
    EXPECT_NEAR(mse(i, r), (0 + 1 + 4 + 0.01 + 0 + 0.04) / 6.0, 1e-7);
    EXPECT_NEAR(rmse(i, r), std::sqrt(5.05 / 6.0), 1e-7);
    // (I-R)^2 / (R^2 + 0.01): 0, 1/1.01, 4/1.01, 0.01/0.02, 0/0.01, 0.04/0.05.
    EXPECT_NEAR(rel_mse(i, r), (5 / 1.01 + 0.5 + 0.8) / 6.0, 1e-6);
    // |I-R| / (|R| + 0.01): 0, 1/1.01, 2/1.01, 0.1/0.11, 0, 0.2/0.21.
    EXPECT_NEAR(mean_abs_rel_error(i, r), (3 / 1.01 + 0.1 / 0.11 + 0.2 / 0.21) / 6.0, 1e-6);
    EXPECT_EQ(rel_mse(r, r), 0.0);
}

TEST(ImageMetrics, MeansPerChannelAndOverall) {
    const Color m = image_mean(rendered());
    EXPECT_FLOAT_EQ(m.x, 0.5f);
    EXPECT_FLOAT_EQ(m.y, 1.f);
    EXPECT_FLOAT_EQ(m.z, 1.5f);
    EXPECT_DOUBLE_EQ(image_mean_overall(rendered()), 1.0);

    Image gray(1, 2, 1);  // one channel counts as gray
    gray.data = {1, 3};
    EXPECT_DOUBLE_EQ(image_mean_overall(gray), 2.0);
}

TEST(ImageMetrics, AlphaIsIgnored) {
    Image i(1, 1, 4), r(1, 1, 3);
    i.data = {1, 1, 1, 0};
    r.data = {1, 1, 1};
    EXPECT_EQ(mse(i, r), 0.0);
}

TEST(ImageMetrics, ErrorMapAveragesToRelMse) {
    const Image i = rendered(), r = reference();
    const Image map = rel_mse_map(i, r);
    ASSERT_EQ(map.channels, 1);
    EXPECT_NEAR(map.at(0, 0, 0), (5 / 1.01) / 3.0, 1e-6);
    EXPECT_NEAR(map.at(1, 0, 0), (0.5 + 0.8) / 3.0, 1e-6);
    EXPECT_NEAR(image_mean_overall(map), rel_mse(i, r), 1e-6);
}

TEST(ImageMetrics, SizeMismatchThrows) {
    Image small(1, 1, 3);
    EXPECT_THROW(rel_mse(rendered(), small), std::invalid_argument);
    EXPECT_THROW(mse(rendered(), small), std::invalid_argument);
    EXPECT_THROW(mean_abs_rel_error(rendered(), small), std::invalid_argument);
    EXPECT_THROW(rel_mse_map(rendered(), small), std::invalid_argument);
}

TEST(ImageMetrics, FalseColorRamp) {
    Image e(4, 1, 1);
    e.data = {0.f, 1.f, 2.f, std::numeric_limits<float>::quiet_NaN()};
    const Image fc = false_color(e, 2.f);
    ASSERT_EQ(fc.channels, 3);
    EXPECT_LT(max_component(fc.rgb(0, 0)), 2e-3f);  // zero: black
    const Color top = fc.rgb(2, 0);                  // max: pale yellow
    EXPECT_GT(top.x, 0.9f);
    EXPECT_GT(top.y, 0.9f);
    EXPECT_LT(top.z, top.y);
    const Color mid = fc.rgb(1, 0);  // half way: reddish
    EXPECT_GT(mid.x, mid.y);
    EXPECT_GT(mid.x, mid.z);
    EXPECT_EQ(fc.rgb(3, 0), Color(0.f, 1.f, 0.f));  // NaN flagged green

    // Automatic scale: the 99th percentile of 0..99 is 99, so 99 maps to the top color.
    Image ramp(100, 1, 1);
    for (int x = 0; x < 100; ++x) ramp.data[x] = float(x);
    EXPECT_EQ(false_color(ramp).rgb(99, 0), false_color(ramp, 99.f).rgb(99, 0));
}
