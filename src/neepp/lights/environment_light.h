// Environment lights: Mitsuba's `envmap` (equirectangular, importance-sampled by luminance) and
// `constant` (uniform radiance from every direction).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>
#include "neepp/base/light.h"
#include "neepp/base/light_steps.h"
#include "neepp/io/image.h"
#include "neepp/math/distribution.h"
#include "neepp/math/transform.h"

namespace neepp {

// The bounding sphere of the scene, which infinite lights emit into (from a disk of its radius).
struct SceneSphere {
    Vec3 center{0.f};
    float radius = 1.f;
    SceneSphere() = default;
    explicit SceneSphere(const BBox &b) : center((b.lo + b.hi) * 0.5f), radius(std::max(1e-3f, 0.5f * norm(b.extent()))) {}
    float disk_pdf() const { return 1.f / (kPi * radius * radius); }
    // A ray toward -d (d points to the sky) from a point of the disk of the sphere's radius, centred on the
    // sphere's centre pushed out along d, perpendicular to d.
    Ray disk_ray(const Vec3 &d, Vec2 u) const;
};

class EnvironmentMapLight final : public Light, public LightSampleSteps {
public:
    // `image` in linear RGB; `to_world` orients the map (Mitsuba: +y is the map's up, u = 0 faces -z).
    EnvironmentMapLight(Image image, const Transform &to_world, float scale);
    DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const override;
    float pdf_direction(const Vec3 &ref, const DirectionSample &ds) const override;
    const LightSampleSteps *steps() const override { return this; }
    void prefetch(Vec2 u) const override { cells_.prefetch(u); }
    LightSampleStart begin(Vec2 u) const override;
    DirectionSample finish(const Vec3 &ref, const LightSampleStart &start, Color &radiance) const override;
    Color eval_environment(const Vec3 &d) const override;
    EmissionSample sample_emission(Vec2 u_pos, Vec2 u_dir) const override;
    EmissionDensity pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &w) const override;
    Color power() const override;
    bool is_infinite() const override { return true; }
    void prepare(const BBox &b) override { sphere_ = SceneSphere(b); }

    // Map between world directions and the map's (u, v) in [0,1)^2 (v = 0 at the top, the +y pole).
    Vec2 direction_to_uv(const Vec3 &d) const;
    // sin_theta (if given) receives the sine of the polar angle, which the direction's pdf divides by.
    Vec3 uv_to_direction(Vec2 uv, float *sin_theta = nullptr) const;

    // Its sampling grid, for samplers that reweight it (NEE++'s per-voxel environment sampling): cells of
    // sampling_width() × sampling_height() over uv (row-major, row 0 at v = 0), drawn from
    // sampling_cells(), uniformly in uv within a cell.
    int sampling_width() const { return sample_w_; }
    int sampling_height() const { return sample_h_; }
    const AliasTable &sampling_cells() const { return cells_; }
    uint32_t sampling_cell(Vec2 uv) const {
        const int x = std::min(int(uv.x * float(sample_w_)), sample_w_ - 1);
        const int y = std::min(int(uv.y * float(sample_h_)), sample_h_ - 1);
        return uint32_t(y) * uint32_t(sample_w_) + uint32_t(x);
    }
    // Cache prefetch of what direction_from_uv(uv) reads (a hint; never changes a result).
    void prefetch_lookup(Vec2 uv) const;
    // The direction sample of map point uv drawn with density pdf_uv (over uv), as sample_direction
    // returns it: direction, solid-angle density, and the radiance arriving along it.
    DirectionSample direction_from_uv(const Vec3 &ref, Vec2 uv, float pdf_uv, Color &radiance) const;
    // The solid-angle density of direction uv's sample when its density over uv is pdf_uv.
    static float solid_angle_density(Vec2 uv, float pdf_uv) {
        const float sin_theta = std::sin(uv.y * kPi);
        return sin_theta > 0 ? pdf_uv / (2.f * kPi * kPi * sin_theta) : 0.f;
    }

private:
    Color lookup(Vec2 uv) const;
    // The map point sample_direction(u) picks and its density in uv (0 where nothing can be sampled).
    Vec2 sample_uv(Vec2 u, float &pdf_uv) const;
    // Texel (x, y) at index y * width + x.
    Color texel(size_t index) const;
    Color texel(int x, int y) const { return texel(size_t(y) * width_ + x); }
    // lookup(uv)'s four texels (wrapping in u, clamped in v) and their weights.
    struct Bilinear {
        size_t i00, i10, i01, i11;
        float w00, w10, w01, w11;
        // The weighted sum of at(index) over the four texels (a colour, or a per-texel luminance).
        template <typename At>
        auto blend(At at) const {
            return at(i00) * w00 + at(i10) * w10 + at(i01) * w01 + at(i11) * w11;
        }
    };
    Bilinear bilinear(Vec2 uv) const;
    // Texels as half floats (RGB, 6 bytes): a 2k map is 12.6 MB instead of 25 MB, so with the sampling
    // table it stays in the last-level cache, where float texels make every sampled direction a miss to
    // memory. Half keeps 11 significant bits, below the noise of any render, and is what most EXR
    // environment maps are stored in; maps beyond half's range stay float.
    int width_ = 0, height_ = 0;
    std::vector<uint16_t> half_;
    std::vector<float> float_;
    Transform to_world_;
    // to_world_ keeps lengths (an envmap's to_world is a rotation, or the identity, in practice): the
    // directions it turns need no normalizing.
    bool keeps_lengths_ = false;
    float scale_;
    static constexpr int kMaxSampleWidth = 1024;
    AliasTable cells_;  // sampling cells (texel cells merged down to at most 1024x512), ∝ luminance × sin(theta)
    int sample_w_ = 0, sample_h_ = 0;
    Color mean_radiance_;
    SceneSphere sphere_;
};

class ConstantEnvironmentLight final : public Light {
public:
    explicit ConstantEnvironmentLight(Color radiance) : radiance_(radiance) {}
    DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const override;
    float pdf_direction(const Vec3 &, const DirectionSample &) const override { return kInv4Pi; }
    Color eval_environment(const Vec3 &) const override { return radiance_; }
    EmissionSample sample_emission(Vec2 u_pos, Vec2 u_dir) const override;
    EmissionDensity pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &) const override {
        return {sphere_.disk_pdf(), kInv4Pi};
    }
    Color power() const override { return radiance_ * (kPi * 4.f * kPi * sphere_.radius * sphere_.radius); }
    bool is_infinite() const override { return true; }
    void prepare(const BBox &b) override { sphere_ = SceneSphere(b); }

private:
    Color radiance_;
    SceneSphere sphere_;
};

// Mitsuba's `point` light: `intensity` in W/sr at `position`.
class PointLight final : public Light {
public:
    PointLight(Vec3 position, Color intensity) : position_(position), intensity_(intensity) {}
    DirectionSample sample_direction(const Vec3 &ref, Vec2 u, Color &radiance) const override;
    float pdf_direction(const Vec3 &, const DirectionSample &) const override { return 0.f; }
    Color power() const override { return intensity_ * (4.f * kPi); }
    EmissionSample sample_emission(Vec2 u_pos, Vec2 u_dir) const override;
    EmissionDensity pdf_emission(const Vec3 &, const Vec3 &, const Vec3 &, const Vec3 &) const override {
        return {1.f, kInv4Pi};
    }
    bool is_delta() const override { return true; }
    std::optional<LightBounds> bounds() const override;
    Vec3 position() const { return position_; }

private:
    Vec3 position_;
    Color intensity_;
};

}  // namespace neepp
