// Arithmetic on eight lanes of one AVX register (one path per lane), for the lane kernels that shade a
// batch's paths together (HitLanes, LightSampleLanes). Names follow the scalar code they mirror,
// so a kernel reads as its scalar counterpart does.
#pragma once
#if defined(__AVX__)
#include <immintrin.h>

namespace neepp::lanes {

using V = __m256;

inline V add(V a, V b) { return _mm256_add_ps(a, b); }
inline V sub(V a, V b) { return _mm256_sub_ps(a, b); }
inline V mul(V a, V b) { return _mm256_mul_ps(a, b); }
inline V mul_add(V a, V b, V c) {  // a b + c
#if defined(__FMA__)
    return _mm256_fmadd_ps(a, b, c);
#else
    return add(mul(a, b), c);
#endif
}
inline V select(V mask, V a, V b) { return _mm256_blendv_ps(b, a, mask); }  // a where mask's sign bit is set
inline V negate(V a) { return _mm256_xor_ps(a, _mm256_set1_ps(-0.f)); }
inline V flip_sign(V a, V sign) { return _mm256_xor_ps(a, sign); }           // sign: -0 (flip) or +0
inline V abs(V a) { return _mm256_andnot_ps(_mm256_set1_ps(-0.f), a); }
inline V dot(V ax, V ay, V az, V bx, V by, V bz) { return mul_add(ax, bx, mul_add(ay, by, mul(az, bz))); }

}  // namespace neepp::lanes
#endif
