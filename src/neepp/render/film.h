// Film: accumulates filter-weighted radiance samples per pixel, as Mitsuba's hdrfilm does (each sample
// splats into the pixels within the reconstruction filter's radius; pixel = Σ w·L / Σ w).
#pragma once
#include <algorithm>
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

private:
    int x0_, y0_, width_, height_;
    const ReconstructionFilter *filter_;
    std::vector<double> sums_;  // per pixel: r, g, b, weight
};

}  // namespace neepp
