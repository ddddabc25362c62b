// Piecewise-constant distributions: discrete (for choosing lights or triangles) and 2D (for environment maps).
#pragma once
#include <cstdint>
#include <vector>
#include "neepp/math/vec.h"

namespace neepp {

class Distribution1D {
public:
    Distribution1D() = default;
    explicit Distribution1D(std::vector<float> weights);
    size_t size() const { return weights_.size(); }
    bool empty() const { return weights_.empty(); }
    float total() const { return total_; }
    // Discrete sampling: returns an index with probability weight[i] / total.
    uint32_t sample_discrete(float u, float *pmf = nullptr) const;
    // Same, and rescales u to a fresh uniform variate in [0,1) for reuse.
    uint32_t sample_reuse(float &u, float *pmf = nullptr) const;
    float pmf(uint32_t i) const { return total_ > 0 ? weights_[i] / total_ : 0.f; }
    // Continuous sampling over [0,1) with a piecewise-constant density; returns the position and its pdf.
    float sample_continuous(float u, float *pdf, uint32_t *index = nullptr) const;
    float pdf_continuous(float x) const;

private:
    std::vector<float> weights_;
    std::vector<double> cdf_;  // cdf_[i] = sum of weights before i, normalized; size n+1
    float total_ = 0;
};

// Piecewise-constant 2D distribution over [0,1)^2 from a row-major grid of weights (rows = y).
class Distribution2D {
public:
    Distribution2D() = default;
    Distribution2D(const std::vector<float> &weights, int width, int height);
    Vec2 sample(Vec2 u, float *pdf) const;
    float pdf(Vec2 p) const;
    int width() const { return width_; }
    int height() const { return height_; }

private:
    std::vector<Distribution1D> conditional_;  // one per row
    Distribution1D marginal_;
    int width_ = 0, height_ = 0;
};

}  // namespace neepp

namespace neepp {

// Walker/Vose alias table: O(1) discrete sampling with two memory reads, for large distributions
// (environment maps with millions of cells) where a binary search's cache misses dominate.
class AliasTable {
public:
    AliasTable() = default;
    explicit AliasTable(const std::vector<float> &weights);
    size_t size() const { return bins_.size(); }
    float total() const { return total_; }
    // Returns an index with probability weight[i] / total. Both 24-bit variates of u are spent on the
    // choice (a single float has too few bits to pick among millions of bins without bias); what is
    // left over comes back in `offset` as a point uniform in [0,1)^2 to ~12 bits per axis, enough to
    // place a sample inside the chosen cell.
    // pmf_out (optional) receives the chosen index's pmf, read from the same cache line.
    uint32_t sample(Vec2 u, Vec2 &offset, float *pmf_out = nullptr) const { return sample_bits(bits_of(u), offset, pmf_out); }
    // The same from 48 random bits (a caller that spent some of u's bits on a choice of its own passes on
    // what is left, rescaled, instead of a float variate with fewer bits than the table needs).
    uint32_t sample_bits(uint64_t bits48, Vec2 &offset, float *pmf_out = nullptr) const;
    // ... or with what is left of the bits after the choice (about 48 − log2(1/pmf) of them random) as 48
    // bits for a choice that follows (a two-level distribution).
    uint32_t sample_bits(uint64_t bits48, uint64_t &rest48, float *pmf_out = nullptr) const;
    // The 48 random bits sample(u) reads: the 24 mantissa bits of each sampler dimension.
    static uint64_t bits_of(Vec2 u) {
        return (uint64_t(double(u.x) * 0x1p24) << 24) | uint64_t(double(u.y) * 0x1p24);
    }
    float pmf(uint32_t i) const { return bins_[i].pmf; }
    // Cache prefetch of the bin sample(u) reads first (a batched caller's latency hiding; a hint only).
    void prefetch(Vec2 u) const { prefetch_bits(bits_of(u)); }
    void prefetch_bits(uint64_t bits48) const { __builtin_prefetch(&bins_[first_index(bits48)]); }
    // The index 48 bits pick before the alias test: the one chosen unless its alias is (for a caller
    // prefetching what it will read of that index).
    uint32_t first_index(uint64_t bits48) const {
        double frac;
        return first_bin(bits48, frac);
    }

private:
    uint32_t choose(uint64_t bits48, double &rest, float *pmf_out) const;
    // The bin 48 random bits pick before the alias test, and the fraction of it left for that test.
    uint32_t first_bin(uint64_t bits, double &frac) const {
        const unsigned __int128 scaled = (unsigned __int128)bits * bins_.size();
        frac = double(uint64_t(scaled) & ((uint64_t(1) << 48) - 1)) * 0x1p-48;
        return uint32_t(scaled >> 48);
    }
    struct Bin {
        float threshold;  // probability of keeping this bin rather than jumping to its alias
        uint32_t alias;
        float pmf;        // weight / total of this bin
        float alias_pmf;  // ... and of its alias, so a sample touches one 16-byte bin, one cache line
    };
    std::vector<Bin> bins_;
    float total_ = 0;
};

}  // namespace neepp
