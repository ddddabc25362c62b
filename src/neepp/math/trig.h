// Sine and cosine of an angle in [-pi/4, pi/4] by polynomial, for the samplers' hot paths (the concentric
// disk behind cosine-weighted and GGX visible-normal sampling): libm's sinf/cosf reduce any argument first
// and cost 2.5 % of a diffuse scene's render. Taylor series to x^9 and x^10: on this range the truncation
// error is below 2e-9 (sin) and 2e-10 (cos), so the result is within about 1 ulp of the exact value
// (tests/math/test_trig.cpp checks it against double precision).
#pragma once

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

}  // namespace neepp
