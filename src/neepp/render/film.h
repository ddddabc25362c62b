// Film: accumulates filter-weighted radiance samples per pixel, as Mitsuba's hdrfilm does (each sample
// splats into the pixels within the reconstruction filter's radius; pixel = Σ w·L / Σ w).
#pragma once
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <cmath>
#include <string>
#include <vector>
#include "neepp/io/image.h"
#include "neepp/math/vec.h"

namespace neepp {

class ReconstructionFilter {
public:
    // type: box, tent, gaussian; radius in pixels (box 0.5, tent 1, gaussian 4·stddev by default)
    ReconstructionFilter(const std::string &type, float radius, float stddev);
    float radius() const { return radius_; }
    // ∫∫ f(x) f(y) dx dy of the separable 2D filter.
    float integral() const;
    // 1D profile; the 2D filter is separable. Inline: the film evaluates it for every pixel a sample touches.
    float eval(float x) const {
        x = std::abs(x);
        switch (type_) {
        case Type::Box: return x <= radius_ ? 1.f : 0.f;
        case Type::Tent: return std::max(0.f, 1.f - x * inv_radius_);
        case Type::Gaussian: return std::max(0.f, std::exp(-0.5f * x * x / (stddev_ * stddev_)) - gauss_offset_);
        }
        return 0.f;
    }

private:
    enum class Type { Box, Tent, Gaussian } type_;
    float radius_, inv_radius_, stddev_, gauss_offset_ = 0;
};

// Where an integrator puts the contributions of a sample that land on other pixels than its own: the
// pass's splat film, or a list the caller weighs first (PSSMLT). Returns false for a value that was not
// added (not finite, or too large), which the caller counts as an invalid sample.
class SplatSink {
public:
    virtual ~SplatSink() = default;
    virtual bool add(float px, float py, const Color &L) = 0;
};

// Contributions that land anywhere on the film, not at the sample's own pixel: light paths connected to
// the camera (light tracing, BDPT's t = 1 strategies). Each splat is spread over the pixels of the filter's
// footprint with weights f / ∫f (pbrt's splat normalization: a splat adds its value, not a weighted
// average), and the image is the sums times a scale the caller knows (pixels / light paths). Sums are
// fixed point (2^-32 steps, int64) and added atomically: integer addition does not depend on the order,
// so the image is the same to the bit whichever thread splatted what, and any thread may splat anywhere.
class SplatFilm final : public SplatSink {
public:
    SplatFilm(int width, int height, const ReconstructionFilter *filter);
    // Thread-safe. Non-finite values, and values too large for the fixed point, are not added: returns
    // false for them (the caller counts them as invalid samples).
    bool add(float px, float py, const Color &L) override;
    // Adds another film's sums (same size).
    void merge(const SplatFilm &other);
    void clear();
    // The sums times scale, per pixel.
    Image resolve(double scale) const;
    // The fixed-point sums (r, g, b per pixel), as a checkpoint stores them, and their restoration.
    std::vector<int64_t> sums() const;
    void set_sums(const std::vector<int64_t> &sums);
    int width() const { return width_; }
    int height() const { return height_; }

private:
    static constexpr double kFixedOne = 4294967296.0;  // 2^32
    // |w·L| per splat beyond this is refused: 2^31 of them still fit an int64 pixel.
    static constexpr double kMaxValue = 1e9;
    int width_, height_;
    const ReconstructionFilter *filter_;
    float inv_integral_;
    std::unique_ptr<std::atomic<int64_t>[]> sums_;  // per pixel: r, g, b
};

// A rectangular block of accumulated samples (a tile plus the filter's border, or the whole image).
class ImageBlock {
public:
    ImageBlock(int x0, int y0, int width, int height, const ReconstructionFilter *filter);
    void clear();
    // Adds sample L at continuous image position (px, py) (pixel (i, j) spans [i, i+1) × [j, j+1)).
    void put(float px, float py, const Color &L);
    // Adds another block's sums (clipped to this block's extent).
    void merge(const ImageBlock &other);
    int x0() const { return x0_; }
    int y0() const { return y0_; }
    int width() const { return width_; }
    int height() const { return height_; }
    // Resolved image: Σ w·L / Σ w per pixel (black where no weight).
    Image resolve() const;
    // The raw sums (r, g, b, weight per pixel, row-major), as a checkpoint stores them; set_sums takes
    // back exactly what sums() gave (throws std::invalid_argument on another size).
    const std::vector<double> &sums() const { return sums_; }
    void set_sums(std::vector<double> sums);

private:
    int x0_, y0_, width_, height_;
    const ReconstructionFilter *filter_;
    std::vector<double> sums_;  // per pixel: r, g, b, weight
};

}  // namespace neepp
