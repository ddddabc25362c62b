#include "neepp/sampling/sampler.h"

#include <stdexcept>

namespace neepp {
namespace {

uint32_t reverse_bits(uint32_t v) {
    v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
    v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
    v = ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
    v = ((v >> 8) & 0x00FF00FFu) | ((v & 0x00FF00FFu) << 8);
    return (v >> 16) | (v << 16);
}

// Nested uniform scrambling of a bit-reversed integer (Laine & Karras 2011; Burley 2020's hash).
uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
    return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

// The first two Sobol dimensions: van der Corput and the (0,2)-sequence's second component.
uint32_t sobol_dim0(uint32_t i) { return reverse_bits(i); }
uint32_t sobol_dim1(uint32_t i) {
    uint32_t v = 1u << 31, r = 0;
    for (; i; i >>= 1, v ^= v >> 1)
        if (i & 1) r ^= v;
    return r;
}

float to_unit(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

}  // namespace

Vec2 SobolSampler::next_2d() {
    // Each dimension pair is a shuffled, scrambled 2D Sobol (0,2)-sequence (Burley 2020): the index is
    // Owen-scrambled per pixel and pair so pairs are decorrelated, the points per pixel stratified.
    uint64_t h = mix_bits(pixel_hash_ ^ (uint64_t(dim_) * 0x9E3779B97F4A7C15ULL));
    dim_ += 2;
    uint32_t idx = nested_uniform_scramble(index_, uint32_t(h));
    uint32_t a = nested_uniform_scramble(sobol_dim0(idx), uint32_t(h >> 32));
    uint32_t b = nested_uniform_scramble(sobol_dim1(idx), uint32_t(h >> 16) ^ 0x5bd1e995u);
    return {to_unit(a), to_unit(b)};
}

float SobolSampler::next_1d() {
    uint64_t h = mix_bits(pixel_hash_ ^ (uint64_t(dim_) * 0x9E3779B97F4A7C15ULL));
    dim_ += 1;
    uint32_t idx = nested_uniform_scramble(index_, uint32_t(h));
    return to_unit(nested_uniform_scramble(sobol_dim0(idx), uint32_t(h >> 32)));
}

std::unique_ptr<Sampler> make_sampler(const std::string &name, uint64_t seed) {
    if (name == "independent") return std::make_unique<IndependentSampler>(seed);
    if (name == "sobol" || name == "stratified" || name == "multijitter" || name == "ldsampler" || name == "orthogonal")
        return std::make_unique<SobolSampler>(seed);
    throw std::invalid_argument("unknown sampler '" + name + "' (supported: independent, sobol, or Mitsuba's stratified, multijitter, ldsampler, orthogonal as sobol)");
}

}  // namespace neepp
