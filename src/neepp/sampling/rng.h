// PCG32 random number generator (O'Neill 2014): small state, good statistical quality, cheap to seed per sample.
#pragma once
#include <cstdint>
#include "neepp/math/vec.h"

namespace neepp {

// 64-bit finalizer (splitmix64) for deriving independent seeds from (seed, pixel, sample) tuples.
inline uint64_t mix_bits(uint64_t v) {
    v ^= v >> 31; v *= 0x7fb5d329728ea185ULL;
    v ^= v >> 27; v *= 0x81dadef4bc2dd44dULL;
    v ^= v >> 33;
    return v;
}

class PCG32 {
public:
    PCG32() { seed(0x853c49e6748fea9bULL, 0xda3e39cb94b95bdbULL); }
    PCG32(uint64_t init_state, uint64_t stream) { seed(init_state, stream); }
    void seed(uint64_t init_state, uint64_t stream) {
        state_ = 0; inc_ = (stream << 1u) | 1u;
        next_u32(); state_ += init_state; next_u32();
    }
    uint32_t next_u32() {
        uint64_t old = state_;
        state_ = old * 6364136223846793005ULL + inc_;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }
    // Uniform float in [0, 1): 24 random mantissa bits.
    float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }
    Vec2 next_2d() { float a = next_float(); return {a, next_float()}; }
    // The whole state, for checkpoints: set_state(state(), increment()) continues the same sequence.
    uint64_t state() const { return state_; }
    uint64_t increment() const { return inc_; }
    void set_state(uint64_t state, uint64_t increment) { state_ = state, inc_ = increment; }

private:
    uint64_t state_, inc_;
};

}  // namespace neepp
