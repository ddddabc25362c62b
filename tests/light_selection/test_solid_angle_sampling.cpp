// Solid-angle sampling of rectangle and sphere lights (light_selection/solid_angle_sampling.h): the
// directions drawn against the density the sampler reports for them (chi-square over the sphere of
// directions, the density integrating to one), each sample's density and radiance against what a ray
// traced along it finds (what MIS and BSDF sampling must agree on), the points where it falls back to the
// light's own sampling (then exactly it), and which lights it takes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>

#include "common/chi2.h"
#include "neepp/light_selection/solid_angle_sampling.h"
#include "neepp/lights/area_light.h"
#include "neepp/shapes/sphere.h"
#include "neepp/shapes/triangle_mesh.h"
#include "neepp/textures/checkerboard_texture.h"

namespace neepp::test {
namespace {

// Radiance that varies over the surface, so a sample that carries another point's radiance is caught.
TexturePtr checker_radiance() {
    return std::make_shared<CheckerboardTexture>(constant_texture(Color(4.f, 2.f, 1.f)), constant_texture(0.5f),
                                                 Transform::scale(Vec3(4.f, 4.f, 1.f)));
}

// The rectangle center ± a ± b (a, b orthogonal), facing cross(a, b), with uvs.
TriangleMesh make_rectangle(const Vec3 &center, const Vec3 &a, const Vec3 &b) {
    TriangleMesh s;
    s.positions = {center - a - b, center + a - b, center + a + b, center - a + b};
    s.uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
    s.indices = {0, 1, 2, 0, 2, 3};
    s.finalize();
    return s;
}
// A 2 x 1 rectangle through the origin facing (0, -0.8, 0.6), as the light tests' own.
TriangleMesh tilted_rectangle() { return make_rectangle(Vec3(0.f), Vec3(1, 0, 0), Vec3(0.f, 0.6f, 0.8f) * 0.5f); }
// 3 x 0.2, turned in space: a thin light, neither square nor aligned with any axis.
TriangleMesh thin_rectangle() {
    const Vec3 a = normalize(Vec3(1.f, 0.4f, -0.3f));
    const Vec3 b = normalize(cross(a, Vec3(0.2f, 1.f, 0.1f)));
    return make_rectangle(Vec3(0.5f, 1.f, -0.2f), a * 1.5f, b * 0.1f);
}

Sphere make_sphere(const Vec3 &center, float radius) {
    Sphere s;
    s.center = center;
    s.radius = radius;
    s.finalize();
    return s;
}

// Nearest hit of a ray with a mesh (Möller-Trumbore in double), completed by the shape's fill_interaction.
std::optional<SurfaceInteraction> intersect(const TriangleMesh &shape, const Ray &ray) {
    std::optional<SurfaceInteraction> best;
    double best_t = kInfinity;
    using D3 = std::array<double, 3>;
    auto sub = [](const Vec3 &a, const Vec3 &b) { return D3{double(a.x) - b.x, double(a.y) - b.y, double(a.z) - b.z}; };
    auto cross3 = [](const D3 &a, const D3 &b) {
        return D3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    };
    auto dot3 = [](const D3 &a, const D3 &b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    const D3 d{ray.d.x, ray.d.y, ray.d.z};
    for (uint32_t prim = 0; prim < shape.triangle_count(); ++prim) {
        const Vec3 &p0 = shape.positions[shape.indices[3 * prim]], &p1 = shape.positions[shape.indices[3 * prim + 1]],
                   &p2 = shape.positions[shape.indices[3 * prim + 2]];
        const D3 e1 = sub(p1, p0), e2 = sub(p2, p0), s = sub(ray.o, p0), pv = cross3(d, e2);
        const double det = dot3(e1, pv);
        if (std::abs(det) < 1e-300) continue;
        const double b1 = dot3(s, pv) / det;
        const D3 qv = cross3(s, e1);
        const double b2 = dot3(d, qv) / det, t = dot3(e2, qv) / det;
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1 || t <= 0 || t >= best_t) continue;
        best_t = t;
        SurfaceInteraction si;
        shape.fill_interaction(prim, float(b1), float(b2), ray, float(t), si);
        best = si;
    }
    return best;
}

// Nearest hit of a ray with a sphere, in double. The direction, unit in float, is not quite unit: from a
// sphere thousands of radii away, the quadratic's discriminant must take its length as it is.
std::optional<SurfaceInteraction> intersect(const Sphere &shape, const Ray &ray) {
    const double ox = double(ray.o.x) - shape.center.x, oy = double(ray.o.y) - shape.center.y,
                 oz = double(ray.o.z) - shape.center.z;
    const double dx = ray.d.x, dy = ray.d.y, dz = ray.d.z;
    const double a = dx * dx + dy * dy + dz * dz, b = ox * dx + oy * dy + oz * dz;
    const double c = ox * ox + oy * oy + oz * oz - double(shape.radius) * shape.radius;
    const double disc = b * b - a * c;
    if (disc < 0) return std::nullopt;
    double t = (-b - std::sqrt(disc)) / a;
    if (t <= 0) t = (-b + std::sqrt(disc)) / a;
    if (t <= 0) return std::nullopt;
    SurfaceInteraction si;
    shape.fill_interaction(0, 0.f, 0.f, ray, float(t), si);
    return si;
}

// A light on a shape, with the sampler under test and a way to trace rays to it.
template <class S>
struct LightSetup {
    S shape;
    std::unique_ptr<AreaLight> light;
    std::unique_ptr<ContextLightSampler> sampler;
    LightSetup(S s, TexturePtr radiance) : shape(std::move(s)) {
        light = std::make_unique<AreaLight>(&shape, std::move(radiance));
        sampler = make_solid_angle_sampler(*light);
    }
    LightSetup(const LightSetup &) = delete;
    std::optional<SurfaceInteraction> trace(const Vec3 &ref, const Vec3 &d) const { return intersect(shape, Ray{ref, d}); }
    // The density MIS gives the point a ray from ref along d finds (0 where it finds none).
    double traced_pdf(const Vec3 &ref, const Vec3 &d) const {
        const auto si = trace(ref, d);
        return si ? sampler->pdf({ref, Vec3(0.f)}, direction_sample_from_hit(ref, *si)) : 0.0;
    }
};

// Directions binned in a band of cos theta around `axis` that holds every direction from ref to the
// shape's points (found from a grid of its area samples), with a margin of a bin and a half.
template <class S>
SphereChi2Config band(const S &shape, const Vec3 &ref, const Vec3 &axis) {
    SphereChi2Config cfg;
    cfg.res = 30;
    cfg.ires = 48;  // silhouettes cut the bins: the quadrature must be fine to get their expected counts
    cfg.sample_count = 300000;
    cfg.frame = Frame(normalize(axis));
    double lo = 1.0, hi = -1.0;
    for (int i = 0; i < 300; ++i)
        for (int j = 0; j < 300; ++j) {
            const Vec3 p = shape.sample_position(Vec2((float(i) + 0.5f) / 300.f, (float(j) + 0.5f) / 300.f)).p;
            const double c = dot(normalize(p - ref), cfg.frame.n);
            lo = std::min(lo, c);
            hi = std::max(hi, c);
        }
    const double margin = 1.5 * (hi - lo) / cfg.res;
    cfg.cos_min = std::max(-1.0, lo - margin);
    cfg.cos_max = std::min(1.0, hi + margin);
    return cfg;
}

template <class S>
Chi2Result chi2_directions(const LightSetup<S> &setup, const Vec3 &ref, const SphereChi2Config &cfg,
                           const DirectionPdf &pdf_override = nullptr) {
    auto sample = [&](PCG32 &rng) -> std::optional<Vec3> {
        Color radiance;
        const DirectionSample ds = setup.sampler->sample({ref, Vec3(0.f)}, rng.next_2d(), radiance);
        if (!(ds.pdf > 0)) return std::nullopt;
        return ds.d;
    };
    auto pdf = [&](const Vec3 &d) { return setup.traced_pdf(ref, d); };
    return chi2_sphere_test(sample, pdf_override ? pdf_override : DirectionPdf(pdf), cfg);
}

bool near_rel(float a, float b, float rel) { return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)); }

// Each sample's density is what pdf() gives it, and what a ray traced along it finds: the same point, the
// same density, the same radiance.
template <class S>
void expect_samples_match_trace(const LightSetup<S> &setup, const Vec3 &ref) {
    PCG32 rng(17, 3);
    int valid = 0, mismatches = 0, misses = 0;
    std::string first;
    for (int k = 0; k < 20000; ++k) {
        Color radiance;
        const DirectionSample ds = setup.sampler->sample({ref, Vec3(0.f)}, rng.next_2d(), radiance);
        if (!(ds.pdf > 0)) {
            ASSERT_TRUE(is_black(radiance));
            continue;
        }
        ++valid;
        ASSERT_NEAR(norm(ds.d), 1.f, 1e-5f);
        // The same number where the spherical rectangle or the cone drew it; by area, the light's own
        // pdf_direction, which rounds its product in another order.
        ASSERT_TRUE(near_rel(setup.sampler->pdf({ref, Vec3(0.f)}, ds), ds.pdf, 1e-5f)) << "sample " << k;
        const auto si = setup.trace(ref, ds.d);
        // From thousands of radii away, the float direction passes up to 1e-4 radii off the point drawn:
        // a ray toward a point that close to the silhouette may miss. A wrong point misses far more often.
        if (!si) {
            ++misses;
            continue;
        }
        ASSERT_LT(norm(si->p - ds.p), 1e-4f * (1.f + ds.dist)) << "sample " << k;
        const float traced = setup.sampler->pdf({ref, Vec3(0.f)}, direction_sample_from_hit(ref, *si));
        const Color seen = setup.light->eval_surface(*si, -ds.d);
        bool ok = near_rel(traced, ds.pdf, 1e-3f);
        for (int c = 0; c < 3; ++c) ok &= near_rel(seen[c], radiance[c], 1e-3f);
        // Round-off moves a few samples across a checker edge when traced back.
        if (!ok && mismatches++ == 0)
            first = "sample " + std::to_string(k) + ": pdf " + std::to_string(ds.pdf) + " traced " + std::to_string(traced) +
                    ", radiance " + std::to_string(radiance[0]) + " traced " + std::to_string(seen[0]);
    }
    EXPECT_GT(valid, 10000);
    EXPECT_LE(misses, valid / 500) << misses << " of " << valid << " sampled directions miss the light";
    EXPECT_LE(mismatches, valid / 1000) << mismatches << " of " << valid << "; first: " << first;
}

// ---- Rectangles ----------------------------------------------------------------------------------

// chi2: whether the direction test applies. Binned in float directions around an axis, a light whose
// directions span a band of cos theta only a few float steps wide cannot be resolved; the far cases' samples
// are checked against their traced density all the same, and the parametrization itself in double
// (tests/math/test_spherical_rectangle.cpp).
struct RectangleCase {
    const char *name;
    TriangleMesh (*make)();
    Vec3 ref;
    bool chi2 = true;
};

// Within kNearDiagonals of the center (the spherical rectangle), then beyond (the light's own sampling,
// through the same sampler).
const RectangleCase kRectangleCases[] = {
    {"front", tilted_rectangle, Vec3(0.2f, -0.45f, 0.45f)},
    {"close", tilted_rectangle, Vec3(0.3f, -0.04f, 0.03f) + Vec3(0.f, 0.6f, 0.8f) * 0.1f},  // 0.05 above it
    {"grazing", tilted_rectangle, Vec3(0.9f, -0.096f, 0.072f)},    // 7 degrees from the center, over its end
    {"edge_on", tilted_rectangle, Vec3(0.9f, -0.0096f, 0.0072f)},  // 0.7 degrees
    {"beside", tilted_rectangle, Vec3(1.05f, -0.04f, 0.03f)},      // past its edge, 0.05 above its plane
    {"thin_turned", thin_rectangle, Vec3(1.1807f, 0.7547f, -0.4942f)},
    {"thin_turned_grazing", thin_rectangle, Vec3(1.6021f, 1.3373f, -0.5486f)},  // 4.8 degrees
    {"grazing_beyond", tilted_rectangle, Vec3(2.5f, -0.24f, 0.18f)},
    {"edge_on_beyond", tilted_rectangle, Vec3(2.5f, -0.024f, 0.018f)},
    {"far", tilted_rectangle, Vec3(3.f, -24.f, 18.f)},                         // 1.7e-3 sr
    {"very_far", tilted_rectangle, Vec3(30.f, -240.f, 180.f), false},          // 2e-5 sr
};
void PrintTo(const RectangleCase &c, std::ostream *os) { *os << c.name; }

class RectangleSolidAngle : public ::testing::TestWithParam<RectangleCase> {};

TEST_P(RectangleSolidAngle, IsUsedAndInFront) {
    const RectangleCase &c = GetParam();
    LightSetup<TriangleMesh> s(c.make(), checker_radiance());
    ASSERT_NE(s.sampler, nullptr);
    const Vec3 n = s.shape.sample_position(Vec2(0.5f, 0.5f)).n;
    EXPECT_GT(dot(c.ref - s.shape.positions[0], n), 0.f) << "the reference point is in front of the light";
}

TEST_P(RectangleSolidAngle, SamplesMatchTracedPdfAndRadiance) {
    const RectangleCase &c = GetParam();
    LightSetup<TriangleMesh> s(c.make(), checker_radiance());
    expect_samples_match_trace(s, c.ref);
}

TEST_P(RectangleSolidAngle, DirectionsFollowPdfWhichIntegratesToOne) {
    const RectangleCase &c = GetParam();
    if (!c.chi2) GTEST_SKIP() << "too narrow a band of directions for float binning";
    LightSetup<TriangleMesh> s(c.make(), checker_radiance());
    // Around the light's back normal: a band of cos theta bounded by smooth curves (the light tests' choice).
    const Chi2Result r = chi2_directions(s, c.ref, band(s.shape, c.ref, -s.shape.sample_position(Vec2(0.5f, 0.5f)).n));
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 5e-3) << r.describe();
    EXPECT_EQ(r.valid_fraction, 1.0) << r.describe();
}

INSTANTIATE_TEST_SUITE_P(Lights, RectangleSolidAngle, ::testing::ValuesIn(kRectangleCases),
                         [](const auto &info) { return std::string(info.param.name); });

// Near the light the density is the spherical rectangle's, one value for every point (where the area
// density varies with cos / distance²); beyond kNearDiagonals diagonals from its center, the area density.
TEST(RectangleSolidAngleCheck, NearPointsTakeTheSphericalRectangle) {
    LightSetup<TriangleMesh> s(tilted_rectangle(), constant_texture(1.f));
    const float diagonal = std::sqrt(5.f);  // of the 2 x 1 rectangle
    const Vec3 n(0.f, -0.8f, 0.6f);
    const float k = RectangleSolidAngleSampler::kNearDiagonals;
    for (const float distance : {0.3f * k * diagonal, 0.95f * k * diagonal, 1.05f * k * diagonal}) {
        const Vec3 ref = n * distance;
        const bool near = distance <= RectangleSolidAngleSampler::kNearDiagonals * diagonal;
        PCG32 rng(2, 7);
        float lo = kInfinity, hi = 0.f;
        for (int k = 0; k < 200; ++k) {
            Color radiance;
            const DirectionSample ds = s.sampler->sample({ref, Vec3(0.f)}, rng.next_2d(), radiance);
            ASSERT_GT(ds.pdf, 0.f);
            lo = std::min(lo, ds.pdf), hi = std::max(hi, ds.pdf);
            if (!near) ASSERT_TRUE(near_rel(ds.pdf, s.light->pdf_direction(ref, ds), 1e-5f));
        }
        if (near) EXPECT_EQ(lo, hi) << "at " << distance;
        else EXPECT_LT(lo, hi) << "at " << distance;
    }
}

// The chi-square test can fail: the area density, reported for the same samples, is refused.
TEST(RectangleSolidAngleCheck, RefusesTheAreaDensity) {
    LightSetup<TriangleMesh> s(tilted_rectangle(), checker_radiance());
    const Vec3 ref(0.2f, -0.45f, 0.45f);
    auto area_pdf = [&](const Vec3 &d) -> double {
        const auto si = s.trace(ref, d);
        return si ? s.light->pdf_direction(ref, direction_sample_from_hit(ref, *si)) : 0.0;
    };
    const Chi2Result r = chi2_directions(s, ref, band(s.shape, ref, -s.shape.sample_position(Vec2(0.5f, 0.5f)).n), area_pdf);
    EXPECT_TRUE(!r.error.empty() || r.p_value < 1e-6) << r.describe();
}

TEST(RectangleSolidAngleCheck, NothingFromBehind) {
    LightSetup<TriangleMesh> s(tilted_rectangle(), constant_texture(1.f));
    for (const Vec3 behind : {Vec3(0.1f, 0.8f, -0.6f), Vec3(0.1f, 0.008f, -0.006f), Vec3(0.3f, 0.f, 0.f)}) {
        PCG32 rng(3, 3);
        for (int k = 0; k < 1000; ++k) {
            Color radiance;
            const DirectionSample ds = s.sampler->sample({behind, Vec3(0.f)}, rng.next_2d(), radiance);
            EXPECT_EQ(ds.pdf, 0.f);
            EXPECT_TRUE(is_black(radiance));
        }
        // A ray from behind that meets the light's back: density 0, as for the light's own sampling.
        const Vec3 d = normalize(Vec3(0.2f, 0.1f, 0.f) - behind);
        if (const auto si = s.trace(behind, d)) {
            EXPECT_EQ(s.sampler->pdf({behind, Vec3(0.f)}, direction_sample_from_hit(behind, *si)), 0.f);
        }
    }
}

// Below kMinSolidAngle the light samples itself: the same samples, densities and radiance, to the bit.
TEST(RectangleSolidAngleCheck, TinySolidAngleFallsBackToAreaSampling) {
    LightSetup<TriangleMesh> s(tilted_rectangle(), checker_radiance());
    const Vec3 ref = Vec3(0.f, -0.8f, 0.6f) * 2000.f;  // 1 / 2000² sr: below the threshold
    PCG32 rng(5, 5);
    for (int k = 0; k < 1000; ++k) {
        const Vec2 u = rng.next_2d();
        Color a, b;
        const DirectionSample x = s.sampler->sample({ref, Vec3(0.f)}, u, a), y = s.light->sample_direction(ref, u, b);
        ASSERT_EQ(x.pdf, y.pdf);
        ASSERT_EQ(norm(x.p - y.p), 0.f);
        ASSERT_EQ(a[0], b[0]);
        ASSERT_EQ(s.sampler->pdf({ref, Vec3(0.f)}, x), s.light->pdf_direction(ref, x));
        ASSERT_GT(x.pdf, 0.f);
    }
}

TEST(RectangleSolidAngleCheck, TakesRectanglesAndSpheresOnly) {
    // A sheared parallelogram, a textured rectangle whose uvs are not affine over it, a flipped sphere:
    // sampled by area (no sampler).
    TriangleMesh sheared = make_rectangle(Vec3(0.f), Vec3(1, 0, 0), Vec3(0.3f, 1.f, 0.f));
    AreaLight sheared_light(&sheared, constant_texture(1.f));
    EXPECT_EQ(make_solid_angle_sampler(sheared_light), nullptr);
    TriangleMesh bent_uv = tilted_rectangle();
    bent_uv.uvs[3] = Vec2(0.f, 0.5f);
    bent_uv.finalize();
    AreaLight bent_textured(&bent_uv, checker_radiance()), bent_uniform(&bent_uv, constant_texture(1.f));
    EXPECT_EQ(make_solid_angle_sampler(bent_textured), nullptr);
    EXPECT_NE(make_solid_angle_sampler(bent_uniform), nullptr) << "a uniform light reads no uv";
    Sphere flipped = make_sphere(Vec3(0.f), 1.f);
    flipped.flip_normals = true;
    AreaLight flipped_light(&flipped, constant_texture(1.f));
    EXPECT_EQ(make_solid_angle_sampler(flipped_light), nullptr);
    // Rotated and scaled unevenly (a Mitsuba rectangle under a to_world), it is still a rectangle.
    TriangleMesh turned = thin_rectangle();
    AreaLight turned_light(&turned, checker_radiance());
    EXPECT_NE(make_solid_angle_sampler(turned_light), nullptr);
}

// ---- Spheres -------------------------------------------------------------------------------------

struct SphereCase {
    const char *name;
    Vec3 ref;
    float tilt;  // of the binning axis from the direction to the center, in radians
    bool chi2 = true;
};

const Vec3 kCenter(0.3f, 1.f, -0.2f);
constexpr float kRadius = 0.5f;

const SphereCase kSphereCases[] = {
    {"near", kCenter + normalize(Vec3(1.f, 0.2f, 0.3f)) * 0.55f, 0.3f},
    {"close", kCenter + normalize(Vec3(-0.3f, 1.f, 0.2f)) * 1.2f, 0.5f},
    {"mid", kCenter + normalize(Vec3(0.2f, -0.5f, 1.f)) * 3.f, 0.2f},
    // Binned around an axis off the cone (half-angle 0.025): around its own axis, float rounding puts
    // directions at cos theta = 1 + 1e-7, outside any band.
    {"far", kCenter + normalize(Vec3(0.4f, 0.2f, -1.f)) * 20.f, 0.06f},
    {"very_far", kCenter + normalize(Vec3(-1.f, 0.3f, 0.4f)) * 3000.f, 0.f, false},
};
void PrintTo(const SphereCase &c, std::ostream *os) { *os << c.name; }

class SphereSolidAngle : public ::testing::TestWithParam<SphereCase> {};

TEST_P(SphereSolidAngle, SamplesMatchTracedPdfAndRadiance) {
    LightSetup<Sphere> s(make_sphere(kCenter, kRadius), checker_radiance());
    ASSERT_NE(s.sampler, nullptr);
    expect_samples_match_trace(s, GetParam().ref);
}

TEST_P(SphereSolidAngle, DirectionsFollowPdfWhichIntegratesToOne) {
    const SphereCase &c = GetParam();
    if (!c.chi2) GTEST_SKIP() << "too narrow a band of directions for float binning";
    LightSetup<Sphere> s(make_sphere(kCenter, kRadius), checker_radiance());
    const Vec3 w = normalize(kCenter - c.ref);
    const Frame f(w);
    const Vec3 axis = w * std::cos(c.tilt) + f.s * std::sin(c.tilt);
    const Chi2Result r = chi2_directions(s, c.ref, band(s.shape, c.ref, axis));
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 5e-3) << r.describe();
    EXPECT_GT(r.valid_fraction, 0.999) << r.describe();
}

INSTANTIATE_TEST_SUITE_P(Lights, SphereSolidAngle, ::testing::ValuesIn(kSphereCases),
                         [](const auto &info) { return std::string(info.param.name); });

TEST(SphereSolidAngleCheck, RefusesTheAreaDensity) {
    LightSetup<Sphere> s(make_sphere(kCenter, kRadius), checker_radiance());
    const Vec3 ref = kCenter + Vec3(0.f, 0.f, 1.2f);
    auto area_pdf = [&](const Vec3 &d) -> double {
        const auto si = s.trace(ref, d);
        return si ? s.light->pdf_direction(ref, direction_sample_from_hit(ref, *si)) : 0.0;
    };
    const Chi2Result r = chi2_directions(s, ref, band(s.shape, ref, normalize(kCenter - ref)), area_pdf);
    EXPECT_TRUE(!r.error.empty() || r.p_value < 1e-6) << r.describe();
}

// Inside the sphere (and on it) there is no cone: the light's own sampling, to the bit.
TEST(SphereSolidAngleCheck, InsideFallsBackToAreaSampling) {
    LightSetup<Sphere> s(make_sphere(kCenter, kRadius), checker_radiance());
    for (const Vec3 ref : {kCenter + Vec3(0.1f, -0.2f, 0.05f), kCenter + Vec3(0.f, kRadius, 0.f)}) {
        PCG32 rng(5, 5);
        for (int k = 0; k < 1000; ++k) {
            const Vec2 u = rng.next_2d();
            Color a, b;
            const DirectionSample x = s.sampler->sample({ref, Vec3(0.f)}, u, a), y = s.light->sample_direction(ref, u, b);
            ASSERT_EQ(x.pdf, y.pdf);
            ASSERT_EQ(norm(x.p - y.p), 0.f);
            ASSERT_EQ(a[1], b[1]);
            ASSERT_EQ(s.sampler->pdf({ref, Vec3(0.f)}, x), s.light->pdf_direction(ref, x));
        }
    }
}

}  // namespace
}  // namespace neepp::test
