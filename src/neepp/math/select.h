// Branch-free choice between two values, for choices that are random (a sampled quadrant, an alias
// table's keep-or-jump): a branch on them is mispredicted about half the time, each miss costing some
// 15 cycles, while this costs a few bit operations. Compilers turn a plain `c ? a : b` on floats back
// into a branch, hence the bit masks.
#pragma once
#include <bit>
#include <cstdint>
#include <type_traits>

namespace neepp {

template <typename T>
inline T select(bool c, T a, T b) {
    static_assert(sizeof(T) == 4 || sizeof(T) == 8);
    using Bits = std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>;
    const Bits mask = Bits(0) - Bits(c);
    return std::bit_cast<T>(Bits((std::bit_cast<Bits>(a) & mask) | (std::bit_cast<Bits>(b) & ~mask)));
}

// v with its sign flipped when c holds.
inline float flip_sign_if(bool c, float v) { return std::bit_cast<float>(std::bit_cast<uint32_t>(v) ^ (uint32_t(c) << 31)); }

}  // namespace neepp
