// Sine and cosine of an angle in [-pi/4, pi/4] by polynomial, for the samplers' hot paths (the concentric
// disk behind cosine-weighted and GGX visible-normal sampling): libm's sinf/cosf reduce any argument first,
// which is costly there. Taylor series to x^9 and x^10: on this range the truncation error is below 2e-9
// (sin) and 2e-10 (cos), so the result is within about 1 ulp of the exact value (tests/math/test_trig.cpp
// checks it against double precision).
#pragma once
#include <cmath>
#include <cstdint>

#include "neepp/math/select.h"
#include "neepp/math/vec.h"

namespace neepp {

struct SinCos {
    float sin, cos;
};

constexpr SinCos sincos_quarter(float x) {
    const float x2 = x * x;
    // Horner in x², exact rational Taylor coefficients 1/n!.
    float s = 1.f / 362880.f;
    s = s * x2 - 1.f / 5040.f;
    s = s * x2 + 1.f / 120.f;
    s = s * x2 - 1.f / 6.f;
    s = s * x2 * x + x;
    float c = -1.f / 3628800.f;
    c = c * x2 + 1.f / 40320.f;
    c = c * x2 - 1.f / 720.f;
    c = c * x2 + 1.f / 24.f;
    c = c * x2 - 0.5f;
    c = c * x2 + 1.f;
    return {s, c};
}

// Sine and cosine of 2π·t, an angle given in turns (as samplers produce them: a variate in [0, 1) times
// 2π), for |t| up to 2^20. The reduction to [-1/8, 1/8] turn is exact in turns: q/4 is a multiple of the
// float spacing at t and lies within 1/8 of it, so t - q/4 needs no rounding. What is left, times 2π,
// falls in sincos_quarter's range, and the quadrant q swaps and negates, by bit operations rather than
// branches (the quadrant of a sampled angle is random, so a branch on it would be mispredicted half the
// time). Far fewer instructions than libm's sincosf (which reduces any argument in radians), within an
// ulp or two of it.
inline SinCos sincos_turns(float t) {
    const float q = std::nearbyint(4.f * t);
    const SinCos r = sincos_quarter((t - 0.25f * q) * (2.f * kPi));
    const uint32_t quadrant = uint32_t(int32_t(q));
    const bool odd = quadrant & 1u;  // sin(x + pi/2) = cos x, cos(x + pi/2) = -sin x
    // The sine is negative in quadrants 2 and 3, the cosine in 1 and 2.
    return {flip_sign_if(quadrant & 2u, select(odd, r.cos, r.sin)),
            flip_sign_if((quadrant + 1u) & 2u, select(odd, r.sin, r.cos))};
}

}  // namespace neepp
