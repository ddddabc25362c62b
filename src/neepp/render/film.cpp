#include "neepp/render/film.h"

#include <cmath>
#include <stdexcept>

namespace neepp {

namespace {
// The first pixel a sample at p reaches: its centre c = i + 0.5 must satisfy c - p > -r, strictly, so
// that a box filter's pixels are half-open, [i, i + 1), as Mitsuba's: a sample (or a splat, which is not
// normalized by the weights) exactly on a pixel boundary counts once, not in both pixels.
inline int first_pixel(float p, float r) { return int(std::floor(p - 0.5f - r)) + 1; }
}  // namespace

ReconstructionFilter::ReconstructionFilter(const std::string &type, float radius, float stddev)
    : radius_(radius), inv_radius_(1.f / radius), stddev_(stddev) {
    if (type == "box") type_ = Type::Box;
    else if (type == "tent") type_ = Type::Tent;
    else if (type == "gaussian") type_ = Type::Gaussian;
    else throw std::invalid_argument("unknown reconstruction filter '" + type + "' (box, tent, gaussian)");
    if (!(radius > 0) || radius > 16) throw std::invalid_argument("filter radius must be in (0, 16]");
    // Mitsuba's gaussian is shifted so it reaches zero at the radius.
    if (type_ == Type::Gaussian) gauss_offset_ = std::exp(-0.5f * radius_ * radius_ / (stddev_ * stddev_));
}

float ReconstructionFilter::integral() const {
    // The 1D profile is piecewise smooth on [-r, r]: a fine midpoint rule is exact to float precision for
    // the box and the tent, and to ~1e-7 for the gaussian.
    constexpr int kSteps = 1 << 14;
    double sum = 0;
    const double h = 2.0 * radius_ / kSteps;
    for (int i = 0; i < kSteps; ++i) sum += eval(float(-radius_ + (i + 0.5) * h));
    sum *= h;
    return float(sum * sum);
}

SplatFilm::SplatFilm(int width, int height, const ReconstructionFilter *filter)
    : width_(width), height_(height), filter_(filter), inv_integral_(1.f / filter->integral()),
      sums_(new std::atomic<int64_t>[size_t(width) * height * 3]) {
    clear();
}

void SplatFilm::clear() {
    for (size_t i = 0; i < size_t(width_) * height_ * 3; ++i) sums_[i].store(0, std::memory_order_relaxed);
}

bool SplatFilm::add(float px, float py, const Color &L) {
    if (!is_finite(L) || !(std::isfinite(px) && std::isfinite(py))) return false;
    const float r = filter_->radius();
    // Pixels whose centre c satisfies -r < c - p <= r (see first_pixel).
    const int ix0 = std::max(0, first_pixel(px, r)), ix1 = std::min(width_ - 1, int(std::floor(px - 0.5f + r)));
    const int iy0 = std::max(0, first_pixel(py, r)), iy1 = std::min(height_ - 1, int(std::floor(py - 0.5f + r)));
    if (std::max({std::abs(L.x), std::abs(L.y), std::abs(L.z)}) * inv_integral_ > kMaxValue) return false;
    for (int y = iy0; y <= iy1; ++y) {
        const float wy = filter_->eval(float(y) + 0.5f - py) * inv_integral_;
        if (wy == 0.f) continue;
        for (int x = ix0; x <= ix1; ++x) {
            const float w = filter_->eval(float(x) + 0.5f - px) * wy;
            if (w == 0.f) continue;
            std::atomic<int64_t> *d = &sums_[(size_t(y) * width_ + x) * 3];
            for (int c = 0; c < 3; ++c) {
                const int64_t v = int64_t(std::llround(double(w) * double(L[c]) * kFixedOne));
                if (v != 0) d[c].fetch_add(v, std::memory_order_relaxed);
            }
        }
    }
    return true;
}

void SplatFilm::merge(const SplatFilm &o) {
    for (size_t i = 0; i < size_t(width_) * height_ * 3; ++i)
        sums_[i].fetch_add(o.sums_[i].load(std::memory_order_relaxed), std::memory_order_relaxed);
}

Image SplatFilm::resolve(double scale) const {
    Image img(width_, height_, 3);
    for (size_t i = 0; i < size_t(width_) * height_ * 3; ++i)
        img.data[i] = float(double(sums_[i].load(std::memory_order_relaxed)) / kFixedOne * scale);
    return img;
}

std::vector<int64_t> SplatFilm::sums() const {
    std::vector<int64_t> out(size_t(width_) * height_ * 3);
    for (size_t i = 0; i < out.size(); ++i) out[i] = sums_[i].load(std::memory_order_relaxed);
    return out;
}

void SplatFilm::set_sums(const std::vector<int64_t> &sums) {
    if (sums.size() != size_t(width_) * height_ * 3) throw std::invalid_argument("SplatFilm::set_sums: wrong size");
    for (size_t i = 0; i < sums.size(); ++i) sums_[i].store(sums[i], std::memory_order_relaxed);
}

void ImageBlock::set_sums(std::vector<double> sums) {
    if (sums.size() != sums_.size()) throw std::invalid_argument("ImageBlock::set_sums: wrong size");
    sums_ = std::move(sums);
}

ImageBlock::ImageBlock(int x0, int y0, int width, int height, const ReconstructionFilter *filter)
    : x0_(x0), y0_(y0), width_(width), height_(height), filter_(filter), sums_(size_t(width) * height * 4, 0.0) {}

void ImageBlock::clear() { std::fill(sums_.begin(), sums_.end(), 0.0); }

namespace {
// A pixel's four sums (r, g, b, weight) as one 256-bit vector: a sample adds w·(L, 1) to each pixel of its
// footprint in one multiply-add, rather than four scalar ones. Unaligned, and may alias the doubles it is
// read from.
typedef double Sums4 __attribute__((vector_size(32), aligned(8), may_alias));
}  // namespace

void ImageBlock::put(float px, float py, const Color &L) {
    float r = filter_->radius();
    // Pixels whose centre (i + 0.5) lies within the radius of the sample (see first_pixel).
    int ix0 = std::max(x0_, first_pixel(px, r)), ix1 = std::min(x0_ + width_ - 1, int(std::floor(px - 0.5f + r)));
    int iy0 = std::max(y0_, first_pixel(py, r)), iy1 = std::min(y0_ + height_ - 1, int(std::floor(py - 0.5f + r)));
    float wx[40], wy[40];
    int nx = ix1 - ix0 + 1, ny = iy1 - iy0 + 1;
    if (nx <= 0 || ny <= 0 || nx > 40 || ny > 40) return;
    for (int i = 0; i < nx; ++i) wx[i] = filter_->eval(float(ix0 + i) + 0.5f - px);
    for (int j = 0; j < ny; ++j) wy[j] = filter_->eval(float(iy0 + j) + 0.5f - py);
    const Sums4 value = {double(L.x), double(L.y), double(L.z), 1.0};
    for (int j = 0; j < ny; ++j) {
        Sums4 *row = reinterpret_cast<Sums4 *>(&sums_[(size_t(iy0 + j - y0_) * width_ + (ix0 - x0_)) * 4]);
        const double wyj = wy[j];
        for (int i = 0; i < nx; ++i) row[i] += (double(wx[i]) * wyj) * value;
    }
}

void ImageBlock::merge(const ImageBlock &o) {
    int xa = std::max(x0_, o.x0_), xb = std::min(x0_ + width_, o.x0_ + o.width_);
    int ya = std::max(y0_, o.y0_), yb = std::min(y0_ + height_, o.y0_ + o.height_);
    for (int y = ya; y < yb; ++y)
        for (int x = xa; x < xb; ++x) {
            double *d = &sums_[(size_t(y - y0_) * width_ + (x - x0_)) * 4];
            const double *s = &o.sums_[(size_t(y - o.y0_) * o.width_ + (x - o.x0_)) * 4];
            for (int c = 0; c < 4; ++c) d[c] += s[c];
        }
}

Image ImageBlock::resolve() const {
    Image img(width_, height_, 3);
    for (size_t i = 0; i < size_t(width_) * height_; ++i) {
        double w = sums_[4 * i + 3];
        for (int c = 0; c < 3; ++c) img.data[3 * i + c] = w > 0 ? float(sums_[4 * i + c] / w) : 0.f;
    }
    return img;
}

}  // namespace neepp
