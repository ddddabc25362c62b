// Triangle hits filled eight at a time (HitLanes): the first step of shading in SoA.
//
// Why: filling a hit record (interpolated position, face and vertex normals, uv, shading frame, wi) is
// scalar arithmetic with two square roots and three divisions per hit, a large share of neepp's own
// work per sample. The kernel below gives each hit one AVX lane. What stays costly is moving data
// between the paths' records (AoS) and the lanes (SoA); 8x8 transposes do it: a triangle's record is
// three rows of 8 floats, and so are the first 24 floats of a hit record.
#include <cstddef>

#include "neepp/shapes/hit_lanes.h"

#include "neepp/math/lanes.h"
#include "neepp/math/transpose.h"

namespace neepp {

namespace {

#if defined(__AVX__)
using namespace lanes;

// b0 a0 + b1 a1 + b2 a2: one coordinate interpolated across the triangle's corners.
inline V interpolate(V a0, V a1, V a2, V b0, V b1, V b2) { return mul_add(a0, b0, mul_add(a1, b1, mul(a2, b2))); }

void fill_kernel(HitLanes &h) {
    // The layouts the transposes assume: a triangle's record is p[3], n[3], uv[3] (24 floats), and the
    // hit record starts with p, t, n, the shading frame (s, t, n), uv, dp/du, dp/dv, wi.
    static_assert(offsetof(SurfaceInteraction, t) == 12 && offsetof(SurfaceInteraction, n) == 16 &&
                  offsetof(SurfaceInteraction, sh_frame) == 28 && offsetof(SurfaceInteraction, uv) == 64 &&
                  offsetof(SurfaceInteraction, dpdu) == 72 && offsetof(SurfaceInteraction, dpdv) == 84 &&
                  offsetof(SurfaceInteraction, wi) == 96);
    static_assert(HitLanes::kLanes == 8, "one lane per float of an AVX register");
    for (int i = h.n; i < HitLanes::kLanes; ++i) {  // unused lanes redo lane 0 (their results are dropped)
        h.tri[i] = h.tri[0];
        h.b1[i] = h.b1[0], h.b2[i] = h.b2[0], h.t[i] = h.t[0], h.dx[i] = h.dx[0], h.dy[i] = h.dy[0], h.dz[i] = h.dz[0];
        h.flip[i] = h.flip[0], h.vertex_normals[i] = h.vertex_normals[0], h.has_uv[i] = h.has_uv[0];
    }
    V c[24];
    for (int row = 0; row < 3; ++row) {
        for (int i = 0; i < 8; ++i) c[8 * row + i] = _mm256_load_ps(h.tri[i] + 8 * row);
        transpose8(c + 8 * row);
    }
    const V p0x = c[0], p0y = c[1], p0z = c[2], p1x = c[3], p1y = c[4], p1z = c[5], p2x = c[6], p2y = c[7],
            p2z = c[8];
    const V n0x = c[9], n0y = c[10], n0z = c[11], n1x = c[12], n1y = c[13], n1z = c[14], n2x = c[15],
            n2y = c[16], n2z = c[17];
    const V uv0x = c[18], uv0y = c[19], uv1x = c[20], uv1y = c[21], uv2x = c[22], uv2y = c[23];

    const V one = _mm256_set1_ps(1.f), zero = _mm256_setzero_ps();
    const V b1 = _mm256_load_ps(h.b1), b2 = _mm256_load_ps(h.b2), b0 = sub(sub(one, b1), b2);
    const V flip = _mm256_load_ps(h.flip);

    // Geometric normal: the corners' winding, flipped if the shape asks.
    const V e1x = sub(p1x, p0x), e1y = sub(p1y, p0y), e1z = sub(p1z, p0z);
    const V e2x = sub(p2x, p0x), e2y = sub(p2y, p0y), e2z = sub(p2z, p0z);
    V gx = sub(mul(e1y, e2z), mul(e1z, e2y)), gy = sub(mul(e1z, e2x), mul(e1x, e2z)),
      gz = sub(mul(e1x, e2y), mul(e1y, e2x));
    const V g_inv = _mm256_div_ps(one, _mm256_sqrt_ps(dot(gx, gy, gz, gx, gy, gz)));
    gx = flip_sign(mul(gx, g_inv), flip), gy = flip_sign(mul(gy, g_inv), flip), gz = flip_sign(mul(gz, g_inv), flip);

    const V px = interpolate(p0x, p1x, p2x, b0, b1, b2), py = interpolate(p0y, p1y, p2y, b0, b1, b2),
            pz = interpolate(p0z, p1z, p2z, b0, b1, b2);
    // Mitsuba's uv on a mesh without texture coordinates is the barycentrics (b1, b2).
    const V has_uv = _mm256_load_ps(h.has_uv);
    const V u = select(has_uv, interpolate(uv0x, uv1x, uv2x, b0, b1, b2), b1),
            v = select(has_uv, interpolate(uv0y, uv1y, uv2y, b0, b1, b2), b2);

    // Shading normal: the interpolated vertex normal, or the geometric one without vertex normals (or
    // where they cancel out).
    V nx = interpolate(n0x, n1x, n2x, b0, b1, b2), ny = interpolate(n0y, n1y, n2y, b0, b1, b2),
      nz = interpolate(n0z, n1z, n2z, b0, b1, b2);
    const V len2 = dot(nx, ny, nz, nx, ny, nz);
    const V use_vertex = _mm256_and_ps(_mm256_load_ps(h.vertex_normals), _mm256_cmp_ps(len2, zero, _CMP_GT_OQ));
    const V n_inv = _mm256_div_ps(one, _mm256_sqrt_ps(len2));
    nx = select(use_vertex, flip_sign(mul(nx, n_inv), flip), gx);
    ny = select(use_vertex, flip_sign(mul(ny, n_inv), flip), gy);
    nz = select(use_vertex, flip_sign(mul(nz, n_inv), flip), gz);

    // The frame around it, as Frame(n) builds it (Duff et al. 2017).
    const V sign = _mm256_or_ps(one, _mm256_and_ps(nz, _mm256_set1_ps(-0.f)));
    const V a = _mm256_div_ps(negate(one), add(sign, nz)), b = mul(mul(nx, ny), a);
    const V sx = mul_add(mul(sign, mul(nx, nx)), a, one), sy = mul(sign, b), sz = negate(mul(sign, nx));
    const V tx = b, ty = mul_add(mul(ny, ny), a, sign), tz = negate(ny);

    // wi: toward where the ray came from, in that frame.
    const V wx = negate(_mm256_load_ps(h.dx)), wy = negate(_mm256_load_ps(h.dy)), wz = negate(_mm256_load_ps(h.dz));
    alignas(32) float wi[3][8];
    _mm256_store_ps(wi[0], dot(wx, wy, wz, sx, sy, sz));
    _mm256_store_ps(wi[1], dot(wx, wy, wz, tx, ty, tz));
    _mm256_store_ps(wi[2], dot(wx, wy, wz, nx, ny, nz));

    // The first 24 floats of each hit record, as three rows per lane (dp/du and dp/dv zero: no tangents).
    V o[24] = {px, py, pz, _mm256_load_ps(h.t), gx, gy, gz, sx,
               sy, sz, tx, ty, tz, nx, ny, nz,
               u, v, zero, zero, zero, zero, zero, zero};
    for (int row = 0; row < 3; ++row) transpose8(o + 8 * row);
    for (int i = 0; i < h.n; ++i) {
        SurfaceInteraction &si = *h.out[i];
        float *record = reinterpret_cast<float *>(&si);
        _mm256_storeu_ps(record, o[i]);
        _mm256_storeu_ps(record + 8, o[8 + i]);
        _mm256_storeu_ps(record + 16, o[16 + i]);
        si.wi = Vec3(wi[0][i], wi[1][i], wi[2][i]);
        si.shape = h.shape[i];
        si.prim_index = h.prim[i];
    }
}
#else
// The scalar fill, lane by lane, on CPUs without AVX.
void fill_kernel(HitLanes &h) {
    for (int i = 0; i < h.n; ++i) {
        const Vec3 d(h.dx[i], h.dy[i], h.dz[i]);
        SurfaceInteraction &si = *h.out[i];
        h.shape[i]->fill_interaction(h.prim[i], h.b1[i], h.b2[i], Ray{Vec3(), d}, h.t[i], si);
        si.wi = si.to_local(-d);
    }
}
#endif

}  // namespace

void fill_lanes(HitLanes &h) {
    if (h.n == 0) return;
    fill_kernel(h);
    h.n = 0;
}

}  // namespace neepp
