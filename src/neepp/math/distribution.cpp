#include "neepp/math/distribution.h"

#include <algorithm>
#include <stdexcept>

#include "neepp/math/select.h"

namespace neepp {

Distribution1D::Distribution1D(std::vector<float> weights) : weights_(std::move(weights)) {
    cdf_.resize(weights_.size() + 1);
    double sum = 0;
    cdf_[0] = 0;
    for (size_t i = 0; i < weights_.size(); ++i) {
        if (!(weights_[i] >= 0) || !std::isfinite(weights_[i])) weights_[i] = 0;  // NaN/inf/negative → 0
        sum += weights_[i];
        cdf_[i + 1] = sum;
    }
    total_ = float(sum);
    if (sum > 0)
        for (auto &c : cdf_) c /= sum;
}

uint32_t Distribution1D::sample_discrete(float u, float *pmf_out) const {
    // First index whose cdf_[i+1] > u; skips zero-weight entries because their cdf does not increase.
    auto it = std::upper_bound(cdf_.begin() + 1, cdf_.end(), double(u));
    uint32_t i = uint32_t(std::min<ptrdiff_t>(it - cdf_.begin() - 1, ptrdiff_t(weights_.size()) - 1));
    while (i > 0 && weights_[i] == 0) --i;  // u at the top edge
    if (pmf_out) *pmf_out = pmf(i);
    return i;
}

uint32_t Distribution1D::sample_reuse(float &u, float *pmf_out) const {
    uint32_t i = sample_discrete(u, pmf_out);
    double lo = cdf_[i], w = cdf_[i + 1] - cdf_[i];
    u = w > 0 ? float(std::clamp((u - lo) / w, 0.0, 0.99999994)) : 0.f;
    return i;
}

float Distribution1D::sample_continuous(float u, float *pdf_out, uint32_t *index) const {
    float ru = u;
    uint32_t i = sample_reuse(ru, nullptr);
    if (index) *index = i;
    size_t n = weights_.size();
    if (pdf_out) *pdf_out = total_ > 0 ? weights_[i] * float(n) / total_ : 0.f;
    return std::min((float(i) + ru) / float(n), 0.99999994f);
}

float Distribution1D::pdf_continuous(float x) const {
    size_t n = weights_.size();
    size_t i = std::min(size_t(std::max(0.f, x) * float(n)), n - 1);
    return total_ > 0 ? weights_[i] * float(n) / total_ : 0.f;
}

Distribution2D::Distribution2D(const std::vector<float> &weights, int width, int height)
    : width_(width), height_(height) {
    if (width <= 0 || height <= 0 || weights.size() != size_t(width) * size_t(height))
        throw std::invalid_argument("Distribution2D: bad dimensions");
    std::vector<float> row_sums(height);
    conditional_.reserve(height);
    for (int y = 0; y < height; ++y) {
        std::vector<float> row(weights.begin() + size_t(y) * width, weights.begin() + size_t(y + 1) * width);
        conditional_.emplace_back(std::move(row));
        row_sums[y] = conditional_.back().total();
    }
    marginal_ = Distribution1D(std::move(row_sums));
}

Vec2 Distribution2D::sample(Vec2 u, float *pdf_out) const {
    float pdf_y, pdf_x;
    uint32_t row;
    float y = marginal_.sample_continuous(u.y, &pdf_y, &row);
    float x = conditional_[row].sample_continuous(u.x, &pdf_x);
    if (pdf_out) *pdf_out = pdf_x * pdf_y;
    return {x, y};
}

float Distribution2D::pdf(Vec2 p) const {
    int row = std::clamp(int(p.y * float(height_)), 0, height_ - 1);
    return marginal_.pdf_continuous(p.y) * conditional_[row].pdf_continuous(p.x);
}

}  // namespace neepp

namespace neepp {

AliasTable::AliasTable(const std::vector<float> &weights) {
    size_t n = weights.size();
    bins_.resize(n);
    double sum = 0;
    for (float w : weights) sum += (w > 0 && std::isfinite(w)) ? w : 0.f;
    total_ = float(sum);
    if (n == 0) return;
    if (!(sum > 0)) throw std::invalid_argument("AliasTable: all weights are zero");
    // Vose's method: scaled probabilities p_i * n split into a "small" (< 1) and a "large" worklist.
    std::vector<double> scaled(n);
    std::vector<uint32_t> small, large;
    for (size_t i = 0; i < n; ++i) {
        double w = (weights[i] > 0 && std::isfinite(weights[i])) ? weights[i] : 0.0;
        bins_[i].pmf = float(w / sum);
        scaled[i] = w / sum * double(n);
        (scaled[i] < 1.0 ? small : large).push_back(uint32_t(i));
    }
    while (!small.empty() && !large.empty()) {
        uint32_t s = small.back(), l = large.back();
        small.pop_back();
        bins_[s].threshold = float(scaled[s]);
        bins_[s].alias = l;
        scaled[l] -= 1.0 - scaled[s];
        if (scaled[l] < 1.0) { large.pop_back(); small.push_back(l); }
    }
    // Leftovers are 1 up to rounding: they keep themselves.
    for (uint32_t i : large) { bins_[i].threshold = 1.f; bins_[i].alias = i; }
    for (uint32_t i : small) { bins_[i].threshold = 1.f; bins_[i].alias = i; }
    for (Bin &b : bins_) b.alias_pmf = bins_[b.alias].pmf;
}

uint32_t AliasTable::choose(uint64_t bits48, double &rest, float *pmf_out) const {
    double frac;
    const uint32_t first = first_bin(bits48, frac);
    const Bin &b = bins_[first];
    // Keep the bin, or jump to its alias: chosen by selects, not a branch, since which way it goes is
    // random (a branch is mispredicted about as often as the bins are split).
    const bool keep = frac < double(b.threshold);
    const double t = b.threshold;
    rest = (frac - select(keep, 0.0, t)) / select(keep, t, 1.0 - t);
    if (pmf_out) *pmf_out = select(keep, b.pmf, b.alias_pmf);
    return select(keep, first, b.alias);
}

uint32_t AliasTable::sample_bits(uint64_t bits48, Vec2 &offset, float *pmf_out) const {
    double rest;
    const uint32_t i = choose(bits48, rest, pmf_out);
    // Split the leftover variate into two: its coarse part and its fine part scaled back up.
    double fine = rest * 4096.0;
    offset = Vec2(float(std::min(rest, 0.99999994)), float(std::min(fine - std::floor(fine), 0.99999994)));
    return i;
}

uint32_t AliasTable::sample_bits(uint64_t bits48, uint64_t &rest48, float *pmf_out) const {
    double rest;
    const uint32_t i = choose(bits48, rest, pmf_out);
    rest48 = std::min(uint64_t(rest * 0x1p48), (uint64_t(1) << 48) - 1);
    return i;
}

}  // namespace neepp
