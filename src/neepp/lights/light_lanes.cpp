#include "neepp/lights/light_lanes.h"

#include "neepp/math/lanes.h"
#include "neepp/math/transpose.h"

namespace neepp {

// What the transposes assume: a record is two rows of 8 floats (p0, e1, e2.xy | e2.z, n, pdf, radiance),
// and a LightSample's first 16 floats are p, n, ns, d, dist, pdf, delta (false: all bits zero), radiance.x.
static_assert(offsetof(LightLaneRecord, n) == 36 && offsetof(LightLaneRecord, pdf) == 48 &&
              offsetof(LightLaneRecord, radiance) == 52);
static_assert(offsetof(DirectionSample, n) == 12 && offsetof(DirectionSample, ns) == 24 &&
              offsetof(DirectionSample, d) == 36 && offsetof(DirectionSample, dist) == 48 &&
              offsetof(DirectionSample, pdf) == 52 && offsetof(DirectionSample, delta) == 56 &&
              offsetof(LightSample, radiance) == 60);

#if defined(__AVX__)
namespace {
using namespace lanes;

void sample_kernel(const float *rx, const float *ry, const float *rz, const float *ux, const float *uy,
                   const LightLaneRecord *const *light, LightSample *const *out, int n) {
    V c[16];
    for (int i = 0; i < 8; ++i) {
        const float *record = reinterpret_cast<const float *>(light[i < n ? i : 0]);  // unused: lane 0's
        c[i] = _mm256_load_ps(record);
        c[8 + i] = _mm256_load_ps(record + 8);
    }
    transpose8(c);
    transpose8(c + 8);
    const V p0x = c[0], p0y = c[1], p0z = c[2], e1x = c[3], e1y = c[4], e1z = c[5], e2x = c[6], e2y = c[7],
            e2z = c[8], nx = c[9], ny = c[10], nz = c[11], area_pdf = c[12];

    // The point, as Shape::sample_position places it, and the way to it from the reference point.
    const V u = _mm256_load_ps(ux), v = _mm256_load_ps(uy);
    const V px = mul_add(e2x, v, mul_add(e1x, u, p0x)), py = mul_add(e2y, v, mul_add(e1y, u, p0y)),
            pz = mul_add(e2z, v, mul_add(e1z, u, p0z));
    V dx = sub(px, _mm256_load_ps(rx)), dy = sub(py, _mm256_load_ps(ry)), dz = sub(pz, _mm256_load_ps(rz));
    const V dist2 = dot(dx, dy, dz, dx, dy, dz), dist = _mm256_sqrt_ps(dist2);
    const V inv_dist = _mm256_div_ps(_mm256_set1_ps(1.f), dist);
    dx = mul(dx, inv_dist), dy = mul(dy, inv_dist), dz = mul(dz, inv_dist);

    // It emits toward the reference point from its front only (AreaLight::emits_toward; here the shading
    // normal is the face's), and not to a point on itself (there d is 0/0, and the comparison with NaN
    // fails); invalid lanes get zero density and radiance.
    const V zero = _mm256_setzero_ps();
    const V cos_light = dot(nx, ny, nz, dx, dy, dz);
    const V valid = _mm256_cmp_ps(cos_light, zero, _CMP_LT_OQ);
    const V pdf = _mm256_and_ps(valid, _mm256_div_ps(mul(area_pdf, dist2), abs(cos_light)));
    const V lx = _mm256_and_ps(valid, c[13]), ly = _mm256_and_ps(valid, c[14]), lz = _mm256_and_ps(valid, c[15]);

    V o[16] = {px, py, pz, nx, ny, nz, nx, ny, nz, dx, dy, dz, dist, pdf, zero, lx};
    transpose8(o);
    transpose8(o + 8);
    alignas(32) float radiance_y[8], radiance_z[8];
    _mm256_store_ps(radiance_y, ly);
    _mm256_store_ps(radiance_z, lz);
    for (int i = 0; i < n; ++i) {
        float *record = reinterpret_cast<float *>(out[i]);
        _mm256_storeu_ps(record, o[i]);
        _mm256_storeu_ps(record + 8, o[8 + i]);
        out[i]->radiance.y = radiance_y[i], out[i]->radiance.z = radiance_z[i];
    }
}
}  // namespace


void LightSampleLanes::flush() {
    if (n_ == 0) return;
    for (int i = n_; i < kLanes; ++i)  // unused lanes redo lane 0 (their results are dropped)
        rx_[i] = rx_[0], ry_[i] = ry_[0], rz_[i] = rz_[0], ux_[i] = ux_[0], uy_[i] = uy_[0];
    sample_kernel(rx_, ry_, rz_, ux_, uy_, light_, out_, n_);
    n_ = 0;
}
#else
void LightSampleLanes::flush() { n_ = 0; }  // nothing is queued without AVX (kEnabled)
#endif

}  // namespace neepp
