#include "neepp/lights/environment_light.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Imath/half.h>
#include "neepp/math/trig.h"
#include "neepp/math/warp.h"

namespace neepp {

EnvironmentMapLight::EnvironmentMapLight(Image image, const Transform &to_world, float scale)
    : to_world_(to_world), keeps_lengths_(to_world.preserves_lengths()), scale_(scale) {
    width_ = image.width, height_ = image.height;
    if (image.width < 2 || image.height < 2) throw std::runtime_error("envmap: image too small");
    const int w = width_, h = height_;
    // Each pass over the texels runs over rows in parallel (on one thread a large map's passes are a
    // good part of a scene's loading); what is summed across rows is summed in row order, so the results
    // do not depend on the thread count.
    auto rows = [](int count, auto &&body) {
        tbb::parallel_for(tbb::blocked_range<int>(0, count), [&](const tbb::blocked_range<int> &r) {
            for (int y = r.begin(); y < r.end(); ++y) body(y);
        });
    };
    // The equirectangular area element of texel row y.
    auto row_sin_theta = [h](int y) { return std::sin(kPi * (float(y) + 0.5f) / float(h)); };
    const float largest = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, h), 0.f,
        [&](const tbb::blocked_range<int> &r, float m) {
            for (int y = r.begin(); y < r.end(); ++y)
                for (int x = 0; x < w; ++x) {
                    const Color c = image.rgb(x, y);
                    for (int k = 0; k < 3; ++k) m = std::max(m, std::abs(c[k]));
                }
            return m;
        },
        [](float a, float b) { return std::max(a, b); });
    // Half floats when every texel fits: half the memory and cache traffic of the lookups.
    const bool halves = std::isfinite(largest) && largest <= float(HALF_MAX);
    if (halves) half_.resize(3 * size_t(w) * h + 1);  // + 1: lookup() loads a texel as four halves
    else float_.resize(3 * size_t(w) * h);
    rows(h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const Color c = image.rgb(x, y);
            const size_t i = 3 * (size_t(y) * w + x);
            for (int k = 0; k < 3; ++k) {
                if (halves) half_[i + k] = imath_float_to_half(c[k]);
                else float_[i + k] = c[k];
            }
        }
    });
    image = Image();  // the texels above are all that is kept
    // Sampling density ∝ luminance × sin(theta) of the row (the equirectangular area element), so the
    // directional pdf stays bounded near the poles. A texel cell (between four texel centres) weighs the
    // mean of its corners' luminance: the integral of the bilinear lookup over it, and positive wherever
    // that lookup is.
    // Luminance is linear in RGB, so that of the bilinear lookup is the bilinear blend of the texels'
    // luminances: blended from one float per texel, and once per cell corner (a corner serves the four
    // cells around it), instead of four RGB lookups of four half texels per cell.
    std::vector<float> texel_lum(size_t(w) * h);
    rows(h, [&](int y) {
        for (int x = 0; x < w; ++x) texel_lum[size_t(y) * w + x] = luminance(texel(x, y));
    });
    std::vector<float> corners(size_t(w + 1) * (h + 1));
    rows(h + 1, [&](int y) {
        for (int x = 0; x <= w; ++x) {
            const float l = bilinear(Vec2(float(x) / float(w), float(y) / float(h))).blend([&](size_t i) {
                return texel_lum[i];
            });
            corners[size_t(y) * (w + 1) + x] = std::max(l, 0.f);
        }
    });
    std::vector<float> weights(size_t(w) * h);
    rows(h, [&](int y) {
        const float sin_theta = row_sin_theta(y);
        const float *c0 = &corners[size_t(y) * (w + 1)], *c1 = c0 + (w + 1);
        for (int x = 0; x < w; ++x)
            weights[size_t(y) * w + x] = (c0[x] + c0[x + 1] + c1[x] + c1[x + 1]) * 0.25f * sin_theta;
    });
    const bool any = std::any_of(weights.begin(), weights.end(), [](float v) { return v > 0; });
    if (!any)  // a black map emits nothing, but sampling it must still be well defined
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) weights[size_t(y) * w + x] = row_sin_theta(y);
    // Sample on a grid of at most kMaxSampleWidth x kMaxSampleWidth/2 cells: a table of 4 MB, where one per
    // texel of a 2k map (16 MB) makes light samples cache misses. A finer grid lowers the variance little
    // and slows sampling. Each coarse cell sums the texel cells it overlaps, so it is positive wherever
    // radiance is; within a cell directions are uniform in uv.
    sample_w_ = std::min(w, kMaxSampleWidth);
    sample_h_ = std::min(h, kMaxSampleWidth / 2);
    std::vector<float> coarse(size_t(sample_w_) * sample_h_, 0.f);
    for (int y = 0; y < h; ++y) {
        int cy0 = int(int64_t(y) * sample_h_ / h), cy1 = int((int64_t(y + 1) * sample_h_ - 1) / h);
        for (int x = 0; x < w; ++x) {
            int cx0 = int(int64_t(x) * sample_w_ / w), cx1 = int((int64_t(x + 1) * sample_w_ - 1) / w);
            for (int cy = cy0; cy <= cy1; ++cy)
                for (int cx = cx0; cx <= cx1; ++cx) coarse[size_t(cy) * sample_w_ + cx] += weights[size_t(y) * w + x];
        }
    }
    cells_ = AliasTable(coarse);
    // Mean radiance over the sphere (for power): integrate with the sin(theta) measure, a sum per row.
    std::vector<Color> row_sums(h);
    rows(h, [&](int y) {
        const float sin_theta = row_sin_theta(y);
        Color acc(0.f);
        for (int x = 0; x < w; ++x) acc += texel(x, y) * sin_theta;
        row_sums[y] = acc;
    });
    Color acc(0.f);
    double norm_w = 0;
    for (int y = 0; y < h; ++y) {
        acc += row_sums[y];
        norm_w += double(row_sin_theta(y)) * w;
    }
    mean_radiance_ = acc * float(scale_ / norm_w);
}

Vec2 EnvironmentMapLight::direction_to_uv(const Vec3 &d_world) const {
    const Vec3 v = to_world_.inverse_vector(d_world);  // not normalized: both angles below ignore its length
    float u = std::atan2(v.x, -v.z) * kInv2Pi;
    if (u < 0) u += 1.f;
    // atan2 keeps precision near the poles, where acos(y) loses it.
    float vv = std::atan2(std::sqrt(v.x * v.x + v.z * v.z), v.y) * kInvPi;
    return {u, vv};
}

Vec3 EnvironmentMapLight::uv_to_direction(Vec2 uv, float *sin_theta) const {
    // theta = pi v and phi = 2 pi u, in turns: v / 2 and u.
    const SinCos t = sincos_turns(0.5f * uv.y), p = sincos_turns(uv.x);
    if (sin_theta) *sin_theta = t.sin;
    const Vec3 d = to_world_.vector(Vec3(t.sin * p.sin, t.cos, -t.sin * p.cos));  // unit before to_world
    return keeps_lengths_ ? d : normalize(d);
}

Color EnvironmentMapLight::texel(size_t index) const {
    const size_t i = 3 * index;
    if (!half_.empty()) return Color(imath_half_to_float(half_[i]), imath_half_to_float(half_[i + 1]),
                                     imath_half_to_float(half_[i + 2]));
    return Color(float_[i], float_[i + 1], float_[i + 2]);
}

// Bilinear lookup with Mitsuba 3's envmap convention: texel (i, j) sits at u = (i + 1/2) / W (the map
// wraps horizontally) and v = j / (H - 1) (the first and last rows lie on the poles).
EnvironmentMapLight::Bilinear EnvironmentMapLight::bilinear(Vec2 uv) const {
    const int w = width_, h = height_;
    float x = uv.x * float(w) - 0.5f, y = uv.y * float(h - 1);
    int x0 = int(std::floor(x)), y0 = std::clamp(int(std::floor(y)), 0, h - 1);
    float fx = x - float(x0), fy = std::clamp(y - float(y0), 0.f, 1.f);
    // u in [0, 1] puts x0 in [-1, w - 1]: one addition wraps it, without the two integer divisions of a
    // modulo (the general case, for u outside, keeps them).
    if (x0 == -1) x0 = w - 1;
    else if (x0 < 0 || x0 >= w) x0 = ((x0 % w) + w) % w;
    int x1 = x0 + 1 == w ? 0 : x0 + 1, y1 = std::min(y0 + 1, h - 1);
    const size_t r0 = size_t(y0) * w, r1 = size_t(y1) * w;
    return {r0 + x0, r0 + x1, r1 + x0, r1 + x1,
            (1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
}

Color EnvironmentMapLight::lookup(Vec2 uv) const {
    const Bilinear b = bilinear(uv);
#if defined(__F16C__)
    // Each texel converted by one instruction, its three halves and the next one's first (the padding
    // half past the last texel keeps that load inside the buffer), and blended in one register.
    if (!half_.empty()) {
        auto at = [&](size_t i, float w) {
            return _mm_mul_ps(_mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i *>(&half_[3 * i]))),
                              _mm_set1_ps(w));
        };
        const __m128 c = _mm_add_ps(_mm_add_ps(at(b.i00, b.w00), at(b.i10, b.w10)),
                                    _mm_add_ps(at(b.i01, b.w01), at(b.i11, b.w11)));
        alignas(16) float out[4];
        _mm_store_ps(out, c);
        return Color(out[0], out[1], out[2]);
    }
#endif
    return b.blend([&](size_t i) { return texel(i); });
}

Color EnvironmentMapLight::eval_environment(const Vec3 &d) const { return lookup(direction_to_uv(d)) * scale_; }

Vec2 EnvironmentMapLight::sample_uv(Vec2 u, float &pdf_uv) const {
    Vec2 offset;
    float pmf;
    const uint32_t cell = cells_.sample(u, offset, &pmf);
    const int w = sample_w_, h = sample_h_;
    pdf_uv = pmf * float(w) * float(h);
    return {(float(cell % w) + offset.x) / float(w), (float(cell / w) + offset.y) / float(h)};
}

LightSampleStart EnvironmentMapLight::begin(Vec2 u) const {
    LightSampleStart start{u};
    start.point = sample_uv(u, start.density);
    prefetch_lookup(start.point);
    return start;
}

void EnvironmentMapLight::prefetch_lookup(Vec2 uv) const {
    // lookup(uv)'s bilinear footprint, which finish reads: in each of its two texel rows, the first
    // and the last byte loaded (two texels and a half, 14 bytes, cross a cache line one time in five, and
    // with the first line only prefetched, misses on the second are a large part of lookup's time).
    const int x = std::min(int(uv.x * float(width_)), width_ - 1);
    const int y = std::min(int(uv.y * float(height_ - 1)), height_ - 1), y1 = std::min(y + 1, height_ - 1);
    for (int row : {y, y1}) {
        const size_t i = 3 * (size_t(row) * width_ + x);
        // (the last byte's index is clamped: past a row's end the footprint wraps, past the map's it stops)
        if (!half_.empty()) __builtin_prefetch(&half_[i]), __builtin_prefetch(&half_[std::min(i + 6, half_.size() - 1)]);
        else __builtin_prefetch(&float_[i]), __builtin_prefetch(&float_[std::min(i + 5, float_.size() - 1)]);
    }
}

DirectionSample EnvironmentMapLight::finish(const Vec3 &ref, const LightSampleStart &start,
                                                   Color &radiance) const {
    return direction_from_uv(ref, start.point, start.density, radiance);
}

DirectionSample EnvironmentMapLight::direction_from_uv(const Vec3 &ref, Vec2 uv, float pdf_uv, Color &radiance) const {
    DirectionSample ds;
    radiance = Color(0.f);
    if (pdf_uv <= 0) return ds;
    float sin_theta;
    const Vec3 d = uv_to_direction(uv, &sin_theta);
    if (sin_theta <= 0) return ds;
    ds.d = d;
    ds.pdf = pdf_uv / (2.f * kPi * kPi * sin_theta);
    ds.dist = kInfinity;
    ds.p = ref + ds.d * (4.f * sphere_.radius);
    radiance = lookup(uv) * scale_;
    return ds;
}

DirectionSample EnvironmentMapLight::sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const {
    return finish(ref, begin(u), radiance);
}

float EnvironmentMapLight::pdf_direction(const Vec3 &, const DirectionSample &ds) const {
    const Vec2 uv = direction_to_uv(ds.d);
    return solid_angle_density(uv, cells_.pmf(sampling_cell(uv)) * float(sample_w_) * float(sample_h_));
}

Color EnvironmentMapLight::power() const {
    return mean_radiance_ * (kPi * 4.f * kPi * sphere_.radius * sphere_.radius);
}

DirectionSample ConstantEnvironmentLight::sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const {
    DirectionSample ds;
    ds.d = square_to_uniform_sphere(u);
    ds.pdf = kInv4Pi;
    ds.dist = kInfinity;
    ds.p = ref + ds.d * (4.f * sphere_.radius);
    radiance = radiance_;
    return ds;
}

DirectionSample PointLight::sample_direction(const Vec3 &ref, Vec2, Color &radiance) const {
    float dist2;
    const DirectionSample ds = direction_sample_to_point(position_, ref, dist2);
    radiance = intensity_ / dist2;  // arriving radiance-equivalent: I / r^2 (the pdf is 1 for the delta)
    return ds;
}

}  // namespace neepp

namespace neepp {

std::optional<LightBounds> PointLight::bounds() const {
    LightBounds b;
    b.bounds.expand(position_);
    b.normals = DirectionCone::entire_sphere();
    b.cos_theta_e = 0.f;  // isotropic: theta_o = pi already covers every direction
    b.phi = luminance(power());
    return b;
}

}  // namespace neepp

namespace neepp {

Ray SceneSphere::disk_ray(const Vec3 &d, Vec2 u) const {
    const Frame frame(d);
    const Vec2 q = square_to_uniform_disk_concentric(u);
    // Pushed out by one more radius than the sphere's: a ray starting on the sphere could begin inside
    // geometry that touches it.
    const Vec3 o = center + (frame.s * q.x + frame.t * q.y) * radius + d * (2.f * radius);
    return Ray{o, -d, 0.f, kInfinity};
}

namespace {
// An infinite light's emitted ray from its direction sample (ds.d toward the sky, density ds.pdf).
EmissionSample infinite_emission(const SceneSphere &sphere, const DirectionSample &ds, const Color &radiance, Vec2 u_pos) {
    EmissionSample es;
    es.ray = sphere.disk_ray(ds.d, u_pos);
    es.p = es.ray.o;
    es.radiance = radiance;
    es.pdf_pos = sphere.disk_pdf();
    es.pdf_dir = ds.pdf;
    return es;
}
}  // namespace

EmissionSample EnvironmentMapLight::sample_emission(Vec2 u_pos, Vec2 u_dir) const {
    Color radiance;
    const DirectionSample ds = sample_direction(sphere_.center, u_dir, radiance);
    if (!(ds.pdf > 0)) return {};
    return infinite_emission(sphere_, ds, radiance, u_pos);
}

EmissionDensity EnvironmentMapLight::pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &w) const {
    return {sphere_.disk_pdf(), pdf_direction(sphere_.center, direction_sample_from_miss(-w))};
}

EmissionSample ConstantEnvironmentLight::sample_emission(Vec2 u_pos, Vec2 u_dir) const {
    Color radiance;
    return infinite_emission(sphere_, sample_direction(sphere_.center, u_dir, radiance), radiance, u_pos);
}

EmissionSample PointLight::sample_emission(Vec2, Vec2 u_dir) const {
    EmissionSample es;
    es.p = position_;
    es.ray = Ray{position_, square_to_uniform_sphere(u_dir), 0.f, kInfinity};
    es.radiance = intensity_;
    es.pdf_pos = 1.f;
    es.pdf_dir = kInv4Pi;
    return es;
}

}  // namespace neepp
