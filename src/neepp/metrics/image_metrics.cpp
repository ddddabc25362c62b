#include "neepp/metrics/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace neepp {

namespace {

constexpr double kRelEpsilon = 0.01;  // the paper's denominator offset

void check_same_size(const Image &img, const Image &ref) {
    if (img.width != ref.width || img.height != ref.height)
        throw std::invalid_argument(fmt::format("image metrics: size mismatch, {}x{} vs reference {}x{}",
                                                img.width, img.height, ref.width, ref.height));
}

// Mean over pixels and RGB channels of term(i, r).
template <typename Term>
double mean_over_rgb(const Image &img, const Image &ref, Term term) {
    check_same_size(img, ref);
    double sum = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const Color a = img.rgb(x, y), b = ref.rgb(x, y);
            for (int c = 0; c < 3; ++c) sum += term(double(a[c]), double(b[c]));
        }
    const size_t n = size_t(img.width) * img.height * 3;
    return n ? sum / double(n) : 0.0;
}

double rel_sq(double i, double r) { return (i - r) * (i - r) / (r * r + kRelEpsilon); }

Color lerp_stops(float t) {
    // Inferno's display (sRGB) colors at t = 0, 1/4, 1/2, 3/4, 1.
    static const Color kStops[5] = {{0.001f, 0.000f, 0.014f}, {0.341f, 0.062f, 0.429f},
                                    {0.735f, 0.216f, 0.330f}, {0.978f, 0.557f, 0.035f},
                                    {0.988f, 0.998f, 0.645f}};
    const float s = std::clamp(t, 0.f, 1.f) * 4.f;
    const int k = std::min(int(s), 3);
    const Color c = lerp(s - float(k), kStops[k], kStops[k + 1]);
    return {srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z)};
}

float percentile_99(const Image &scalar) {
    std::vector<float> v;
    v.reserve(size_t(scalar.width) * scalar.height);
    for (int y = 0; y < scalar.height; ++y)
        for (int x = 0; x < scalar.width; ++x)
            if (std::isfinite(scalar.at(x, y, 0))) v.push_back(scalar.at(x, y, 0));
    if (v.empty()) return 1.f;
    const size_t k = std::min(v.size() - 1, size_t(0.99 * double(v.size())));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    // Error confined to under 1% of the pixels: scale by the largest value instead of showing black.
    return v[k] > 0.f ? v[k] : *std::max_element(v.begin(), v.end());
}

}  // namespace

double rel_mse(const Image &img, const Image &ref) { return mean_over_rgb(img, ref, rel_sq); }

double mse(const Image &img, const Image &ref) {
    return mean_over_rgb(img, ref, [](double i, double r) { return (i - r) * (i - r); });
}

double rmse(const Image &img, const Image &ref) { return std::sqrt(mse(img, ref)); }

double mean_abs_rel_error(const Image &img, const Image &ref) {
    return mean_over_rgb(img, ref, [](double i, double r) { return std::abs(i - r) / (std::abs(r) + kRelEpsilon); });
}

Color image_mean(const Image &img) {
    double sum[3] = {0, 0, 0};
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const Color c = img.rgb(x, y);
            for (int k = 0; k < 3; ++k) sum[k] += c[k];
        }
    const double n = std::max<double>(1.0, double(img.width) * img.height);
    return {float(sum[0] / n), float(sum[1] / n), float(sum[2] / n)};
}

double image_mean_overall(const Image &img) {
    const Color m = image_mean(img);
    return (double(m.x) + double(m.y) + double(m.z)) / 3.0;
}

Image rel_mse_map(const Image &img, const Image &ref) {
    check_same_size(img, ref);
    Image out(img.width, img.height, 1);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const Color a = img.rgb(x, y), b = ref.rgb(x, y);
            double sum = 0;
            for (int c = 0; c < 3; ++c) sum += rel_sq(a[c], b[c]);
            out.at(x, y, 0) = float(sum / 3.0);
        }
    return out;
}

Image false_color(const Image &scalar, float max_value) {
    const float scale = max_value > 0.f ? max_value : percentile_99(scalar);
    const float inv = scale > 0.f ? 1.f / scale : 0.f;
    Image out(scalar.width, scalar.height, 3);
    for (int y = 0; y < scalar.height; ++y)
        for (int x = 0; x < scalar.width; ++x) {
            const float v = scalar.at(x, y, 0);
            const Color c = std::isfinite(v) ? lerp_stops(v * inv) : Color(0.f, 1.f, 0.f);
            for (int k = 0; k < 3; ++k) out.at(x, y, k) = c[k];
        }
    return out;
}

}  // namespace neepp
