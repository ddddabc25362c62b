// Direction sampling of area and environment lights, from reference points in front of them and at
// grazing angles: sample_direction's distribution against pdf_direction (chi-square over the sphere of
// directions), and each sample's pdf and radiance against what a ray traced along it would see — the
// quantities that next event estimation and BSDF sampling must agree on for MIS.
#include <gtest/gtest.h>

#include <sstream>

#include "common/chi2.h"
#include "neepp/shapes/triangle_mesh.h"
#include "neepp/lights/area_light.h"
#include "neepp/lights/environment_light.h"
#include "neepp/textures/checkerboard_texture.h"
#include "neepp/math/warp.h"

namespace neepp::test {
namespace {

// What a ray from a reference point along a direction sees of a light: the DirectionSample that
// direction_sample_from_hit / _from_miss build in the integrator, and the radiance arriving along it.
struct Seen {
    DirectionSample ds;
    Color radiance;
};
using Trace = std::function<std::optional<Seen>(const Vec3 &ref, const Vec3 &d)>;

// Nearest hit of a ray with a mesh shape (Möller-Trumbore in double precision), completed by the
// shape's own fill_interaction as Embree hits are.
std::optional<SurfaceInteraction> intersect(const TriangleMesh &shape, const Ray &ray) {
    std::optional<SurfaceInteraction> best;
    double best_t = kInfinity;
    using D3 = std::array<double, 3>;
    auto sub = [](const Vec3 &a, const Vec3 &b) {
        return D3{double(a.x) - b.x, double(a.y) - b.y, double(a.z) - b.z};
    };
    auto cross3 = [](const D3 &a, const D3 &b) {
        return D3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    };
    auto dot3 = [](const D3 &a, const D3 &b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    const D3 d{ray.d.x, ray.d.y, ray.d.z};
    for (uint32_t prim = 0; prim < shape.triangle_count(); ++prim) {
        const Vec3 &p0 = shape.positions[shape.indices[3 * prim]], &p1 = shape.positions[shape.indices[3 * prim + 1]],
                   &p2 = shape.positions[shape.indices[3 * prim + 2]];
        auto e1 = sub(p1, p0), e2 = sub(p2, p0), s = sub(ray.o, p0);
        auto pv = cross3(d, e2);
        double det = dot3(e1, pv);
        if (std::abs(det) < 1e-300) continue;
        double b1 = dot3(s, pv) / det;
        auto qv = cross3(s, e1);
        double b2 = dot3(d, qv) / det, t = dot3(e2, qv) / det;
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1 || t <= 0 || t >= best_t) continue;
        best_t = t;
        SurfaceInteraction si;
        shape.fill_interaction(prim, float(b1), float(b2), ray, float(t), si);
        best = si;
    }
    return best;
}

Trace trace_area(const TriangleMesh &shape, const AreaLight &light) {
    return [&shape, &light](const Vec3 &ref, const Vec3 &d) -> std::optional<Seen> {
        std::optional<SurfaceInteraction> si = intersect(shape, Ray{ref, d});
        if (!si) return std::nullopt;
        return Seen{direction_sample_from_hit(ref, *si), light.eval_surface(*si, -d)};
    };
}

Trace trace_environment(const Light &light) {
    return [&light](const Vec3 &, const Vec3 &d) -> std::optional<Seen> {
        return Seen{direction_sample_from_miss(d), light.eval_environment(d)};
    };
}

bool near_rel(float a, float b, float rel, float abs = 0.f) {
    return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)) + abs;
}
bool near_rel(const Color &a, const Color &b, float rel, float abs = 0.f) {
    return near_rel(a.x, b.x, rel, abs) && near_rel(a.y, b.y, rel, abs) && near_rel(a.z, b.z, rel, abs);
}

std::string str(const Vec3 &v) {
    std::ostringstream os;
    os << "(" << v.x << "," << v.y << "," << v.z << ")";
    return os.str();
}

// Each sample's pdf and radiance must be those that tracing its direction reproduces. Round-off moves a
// few samples across a texel or checker edge when their direction is traced back, so a small fraction
// of disagreements is tolerated; a wrong formula disagrees on a large share of the samples.
void expect_samples_match_trace(const Light &light, const Vec3 &ref, const Trace &trace, int count = 20000) {
    PCG32 rng(99, 1);
    int valid = 0, mismatches = 0;
    std::string first_mismatch;
    auto check = [&](bool ok, int k, const std::string &what) {
        if (ok) return;
        if (mismatches++ == 0) first_mismatch = "sample " + std::to_string(k) + ": " + what;
    };
    for (int k = 0; k < count; ++k) {
        Color radiance;
        DirectionSample ds = light.sample_direction(ref, rng.next_2d(), radiance);
        if (ds.pdf == 0) {
            ASSERT_TRUE(is_black(radiance)) << "invalid sample " << k << " carries radiance";
            continue;
        }
        ++valid;
        ASSERT_NEAR(norm(ds.d), 1.f, 1e-5f);
        float own_pdf = light.pdf_direction(ref, ds);
        check(near_rel(own_pdf, ds.pdf, 1e-3f), k,
              "pdf " + std::to_string(ds.pdf) + " vs pdf_direction " + std::to_string(own_pdf));
        std::optional<Seen> seen = trace(ref, ds.d);
        ASSERT_TRUE(seen) << "sample " << k << ": a ray along the sampled direction misses the light";
        if (!light.is_infinite()) {
            ASSERT_LT(norm(seen->ds.p - ds.p), 1e-4f * (1.f + ds.dist)) << "sample " << k;
        }
        float traced_pdf = light.pdf_direction(ref, seen->ds);
        check(near_rel(traced_pdf, ds.pdf, 1e-3f), k,
              "pdf " + std::to_string(ds.pdf) + " vs traced " + std::to_string(traced_pdf));
        check(near_rel(radiance, seen->radiance, 1e-3f, 1e-3f), k,
              "radiance " + str(radiance) + " vs traced " + str(seen->radiance) + " along " + str(ds.d));
    }
    EXPECT_GT(valid, count / 2);
    EXPECT_LE(mismatches, valid / 1000) << mismatches << " disagreements in " << valid << " samples; first: "
                                        << first_mismatch;
}

Chi2Result chi2_light(const Light &light, const Vec3 &ref, const Trace &trace, SphereChi2Config cfg) {
    auto sample = [&](PCG32 &rng) -> std::optional<Vec3> {
        Color radiance;
        DirectionSample ds = light.sample_direction(ref, rng.next_2d(), radiance);
        if (ds.pdf == 0) return std::nullopt;
        return ds.d;
    };
    auto pdf = [&](const Vec3 &d) -> double {
        std::optional<Seen> seen = trace(ref, d);
        return seen ? light.pdf_direction(ref, seen->ds) : 0.0;
    };
    return chi2_sphere_test(sample, pdf, cfg);
}

// ---- Area lights --------------------------------------------------------------------------------

// Radiance varies over the surface, so a sample that reports the radiance of another point is caught.
TexturePtr checker_radiance() {
    return std::make_shared<CheckerboardTexture>(constant_texture(Color(4.f, 2.f, 1.f)), constant_texture(0.5f),
                                                 Transform::scale(Vec3(4.f, 4.f, 1.f)));
}

// A 2 x 1 rectangle through the origin, tilted so that its normal is (0, -0.8, 0.6), with texture
// coordinates.
TriangleMesh make_rectangle() {
    TriangleMesh s;
    Vec3 e1(1.f, 0.f, 0.f), e2 = Vec3(0.f, 0.6f, 0.8f) * 0.5f;
    s.positions = {-e1 - e2, e1 - e2, e1 + e2, -e1 + e2};
    s.uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
    s.indices = {0, 1, 2, 0, 2, 3};
    s.finalize();
    return s;
}

// The same rectangle with texture coordinates that are not affine over it (one corner's uv moved): a
// point's uv is then the hit triangle's interpolation, which sampling must reproduce triangle by triangle.
TriangleMesh make_rectangle_bent_uv() {
    TriangleMesh s = make_rectangle();
    s.uvs[3] = Vec2(0.f, 0.5f);
    s.finalize();
    return s;
}

// The rectangle with vertex normals leaning 60 degrees toward -e1 at one end and +e1 at the other: the side
// its shading normal faces, which emits, then varies over it (Mitsuba's convention), and a reference point
// off to one side sees part of the front face dark.
TriangleMesh make_rectangle_bent_normals() {
    TriangleMesh s = make_rectangle();
    const Vec3 n = normalize(cross(s.positions[1] - s.positions[0], s.positions[2] - s.positions[0]));
    const Vec3 e1 = normalize(s.positions[1] - s.positions[0]);
    const Vec3 left = n * 0.5f - e1 * 0.866f, right = n * 0.5f + e1 * 0.866f;
    s.normals = {left, right, right, left};
    s.finalize();
    return s;
}

// Two triangles sharing a diagonal, of areas 0.5 and 1.5, that do not form a parallelogram.
TriangleMesh make_kite() {
    TriangleMesh s;
    s.positions = {{0, 0, 0}, {1, -0.4f, 0}, {2.5f, 0, 0}, {1, 1.2f, 0}};
    s.uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
    s.indices = {0, 1, 2, 0, 2, 3};
    s.finalize();
    return s;
}

// Coplanar triangles (z = 0) whose areas differ by a factor of 1600, one of them wound to face away
// (-z), and no texture coordinates. Coplanar and disjoint, they never overlap as seen from a point, so
// each direction shows at most one point of the light, as the per-point pdf_direction assumes.
TriangleMesh make_uneven_mesh() {
    TriangleMesh s;
    s.positions = {{0, 0, 0},       {2, 0, 0},      {0, 2, 0},        // area 2
                   {2.1f, 0, 0},    {2.15f, 0, 0},  {2.1f, 0.05f, 0},  // area 0.00125
                   {0.5f, 2.2f, 0}, {1.5f, 2.2f, 0}, {1.5f, 2.7f, 0},  // area 0.25
                   {2.2f, 1, 0},    {2.2f, 2, 0},   {3, 1, 0}};        // area 0.4, facing -z
    s.indices = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
    s.finalize();
    return s;
}

// Bins directions around the normal of a planar light's back side, where cos theta = h / r for a point at
// distance r from a reference point at height h above the plane: the light becomes a band of cos theta,
// bounded by smooth curves even when seen at grazing angles, whereas around any axis through the light a
// thin light crosses the pole of the bins, which Simpson's rule cannot integrate. The band is limited to
// the light's range of cos theta (found by sampling its surface), with a margin of a bin and a half, so
// that its narrow support spans many bins.
SphereChi2Config band_below(const Shape &shape, const Vec3 &ref) {
    SphereChi2Config cfg;
    cfg.res = 30;
    cfg.ires = 48;  // silhouettes cut the bins: the quadrature must be fine to get their expected counts
    cfg.sample_count = 300000;
    cfg.frame = Frame(-shape.sample_position(Vec2(0.5f, 0.5f)).n);
    double lo = 1.0, hi = -1.0;
    for (int i = 0; i < 300; ++i)
        for (int j = 0; j < 300; ++j) {
            Vec3 p = shape.sample_position(Vec2((float(i) + 0.5f) / 300.f, (float(j) + 0.5f) / 300.f)).p;
            double c = dot(normalize(p - ref), cfg.frame.n);
            lo = std::min(lo, c);
            hi = std::max(hi, c);
        }
    double margin = 1.5 * (hi - lo) / cfg.res;
    cfg.cos_min = std::max(-1.0, lo - margin);
    cfg.cos_max = std::min(1.0, hi + margin);
    return cfg;
}

struct AreaCase {
    const char *name;
    TriangleMesh (*make)();
    Vec3 ref;
};

const AreaCase kAreaCases[] = {
    {"rectangle_front", make_rectangle, Vec3(0.2f, -0.45f, 0.45f)},
    {"rectangle_grazing_along_e1", make_rectangle, Vec3(2.5f, -0.24f, 0.18f)},   // 7 degrees above the plane
    {"rectangle_grazing_along_e2", make_rectangle, Vec3(0.3f, 1.56f, 2.58f)},    // 6 degrees
    {"rectangle_edge_on", make_rectangle, Vec3(2.5f, -0.024f, 0.018f)},  // 0.7 degrees
    {"rectangle_bent_uv_front", make_rectangle_bent_uv, Vec3(0.2f, -0.45f, 0.45f)},
    {"rectangle_bent_normals_front", make_rectangle_bent_normals, Vec3(0.2f, -0.45f, 0.45f)},
    {"rectangle_bent_normals_aside", make_rectangle_bent_normals, Vec3(2.5f, -0.3f, 0.6f)},
    {"kite_front", make_kite, Vec3(1.f, 0.3f, 1.f)},
    {"kite_grazing", make_kite, Vec3(-1.5f, 0.4f, 0.3f)},
    {"uneven_mesh_front", make_uneven_mesh, Vec3(1.f, 1.f, 1.5f)},
    {"uneven_mesh_grazing", make_uneven_mesh, Vec3(-1.5f, 1.2f, 0.5f)},           // 6 to 18 degrees
    {"uneven_mesh_edge_on", make_uneven_mesh, Vec3(-1.5f, 1.2f, 0.05f)},
};

void PrintTo(const AreaCase &c, std::ostream *os) { *os << c.name; }

class AreaLightSampling : public ::testing::TestWithParam<AreaCase> {};

TEST_P(AreaLightSampling, SamplesMatchTracedPdfAndRadiance) {
    const AreaCase &c = GetParam();
    TriangleMesh shape = c.make();
    AreaLight light(&shape, checker_radiance());
    expect_samples_match_trace(light, c.ref, trace_area(shape, light));
}

TEST_P(AreaLightSampling, DirectionsFollowPdf) {
    const AreaCase &c = GetParam();
    TriangleMesh shape = c.make();
    AreaLight light(&shape, checker_radiance());
    Chi2Result r = chi2_light(light, c.ref, trace_area(shape, light), band_below(shape, c.ref));
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
    // Samples lost to the back-facing triangle are exactly the pdf mass missing from the sphere.
    EXPECT_NEAR(r.pdf_integral, r.valid_fraction, 5e-3) << r.describe();
}

INSTANTIATE_TEST_SUITE_P(Lights, AreaLightSampling, ::testing::ValuesIn(kAreaCases),
                         [](const ::testing::TestParamInfo<AreaCase> &info) { return std::string(info.param.name); });

// A parallelogram is sampled as one (no triangle chosen): the point and its uv are affine in u, which
// the per-triangle mapping is not. With uvs that are not affine over it, a sample that needs its uv takes
// the triangles' way, and one that does not still the parallelogram's.
TEST(AreaLight, ParallelogramSamplesAreAffineInU) {
    auto affine = [](const TriangleMesh &shape, bool with_uv) {
        const PositionSample o = shape.sample_position(Vec2(0.f, 0.f), with_uv),
                             a = shape.sample_position(Vec2(1.f, 0.f), with_uv),
                             b = shape.sample_position(Vec2(0.f, 1.f), with_uv);
        PCG32 rng(5, 2);
        bool ok = true;
        for (int k = 0; k < 100; ++k) {
            const Vec2 u = rng.next_2d();
            const PositionSample ps = shape.sample_position(u, with_uv);
            ok &= norm(ps.p - (o.p + (a.p - o.p) * u.x + (b.p - o.p) * u.y)) < 1e-5f;
            if (with_uv) {
                const Vec2 uv = o.uv + (a.uv - o.uv) * u.x + (b.uv - o.uv) * u.y;
                ok &= std::abs(ps.uv.x - uv.x) + std::abs(ps.uv.y - uv.y) < 1e-5f;
            }
            EXPECT_NEAR(ps.pdf, 1.f / shape.surface_area(), 1e-6f);
        }
        return ok;
    };
    EXPECT_TRUE(affine(make_rectangle(), true));
    EXPECT_TRUE(affine(make_rectangle_bent_uv(), false));
    EXPECT_FALSE(affine(make_rectangle_bent_uv(), true));
    EXPECT_FALSE(affine(make_kite(), false));
}

TEST(AreaLight, UnevenMeshLosesExactlyTheBackFacingArea) {
    // Sanity of the case above: the one back-facing triangle holds 0.4 of the 2.65125 total area.
    TriangleMesh shape = make_uneven_mesh();
    EXPECT_NEAR(shape.surface_area(), 2.65125f, 1e-5f);
    AreaLight light(&shape, constant_texture(1.f));
    const Vec3 ref(1.f, 1.f, 1.5f);
    Chi2Result r = chi2_light(light, ref, trace_area(shape, light), band_below(shape, ref));
    EXPECT_NEAR(r.valid_fraction, 1.0 - 0.4 / 2.65125, 5e-3) << r.describe();
}

TEST(AreaLight, ShadingNormalDecidesTheSideThatEmits) {
    // Seen from far along +e1 and a little above, the end of the bent rectangle whose normals lean toward
    // -e1 faces away, though the face itself is seen from the front: the light shows only its other part.
    TriangleMesh shape = make_rectangle_bent_normals();
    AreaLight light(&shape, constant_texture(1.f));
    const Vec3 ref(6.f, -0.3f, 0.4f);
    int lit = 0, dark = 0;
    PCG32 rng(9, 1);
    for (int k = 0; k < 4000; ++k) {
        Color radiance;
        const DirectionSample ds = light.sample_direction(ref, rng.next_2d(), radiance);
        ASSERT_LT(dot(ds.n, ds.d), 0.f) << "the face is seen from its front";
        const bool emits = dot(ds.ns, ds.d) < 0.f;
        EXPECT_EQ(emits, ds.pdf > 0.f);
        EXPECT_EQ(emits, !is_black(radiance));
        (emits ? lit : dark)++;
    }
    EXPECT_GT(lit, 400);
    EXPECT_GT(dark, 400);
}

TEST(AreaLight, BackSideIsDark) {
    TriangleMesh shape = make_rectangle();
    AreaLight light(&shape, constant_texture(1.f));
    Vec3 behind(0.1f, 0.8f, -0.6f);  // -normal side
    PCG32 rng(3, 3);
    for (int k = 0; k < 1000; ++k) {
        Color radiance;
        DirectionSample ds = light.sample_direction(behind, rng.next_2d(), radiance);
        EXPECT_EQ(ds.pdf, 0.f);
        EXPECT_TRUE(is_black(radiance));
        EXPECT_EQ(light.pdf_direction(behind, ds), 0.f);
    }
}

// ---- Environment lights -------------------------------------------------------------------------

constexpr int kEnvW = 32, kEnvH = 16;

// A smooth coloured background, a bright 2x2 spot and a black block.
Image make_env_image() {
    Image img(kEnvW, kEnvH, 3);
    for (int y = 0; y < kEnvH; ++y)
        for (int x = 0; x < kEnvW; ++x) {
            float base = 0.3f + 0.2f * std::sin(float(x) * 0.4f) * std::cos(float(y) * 0.5f);
            img.at(x, y, 0) = base;
            img.at(x, y, 1) = base * 0.8f + 0.05f * float(y) / kEnvH;
            img.at(x, y, 2) = base * 0.6f;
        }
    for (int y = 4; y <= 5; ++y)
        for (int x = 20; x <= 21; ++x)
            for (int ch = 0; ch < 3; ++ch) img.at(x, y, ch) = 40.f - 10.f * float(ch);
    for (int y = 9; y <= 13; ++y)
        for (int x = 3; x <= 12; ++x)
            for (int ch = 0; ch < 3; ++ch) img.at(x, y, ch) = 0.f;
    return img;
}

const Transform kEnvToWorld = Transform::rotate(Vec3(1.f, 2.f, 0.5f), 37.f);
constexpr float kEnvScale = 1.5f;

SphereChi2Config full_sphere() {
    SphereChi2Config cfg;
    cfg.res = 64;
    cfg.ires = 16;  // the map's texel edges cut the bins
    cfg.sample_count = 500000;
    return cfg;
}

TEST(EnvironmentMapLight, SamplesMatchTracedPdfAndRadiance) {
    EnvironmentMapLight light(make_env_image(), kEnvToWorld, kEnvScale);
    expect_samples_match_trace(light, Vec3(1.f, 2.f, 3.f), trace_environment(light));
}

TEST(EnvironmentMapLight, DirectionsFollowPdfWhichIntegratesToOne) {
    EnvironmentMapLight light(make_env_image(), kEnvToWorld, kEnvScale);
    Chi2Result r = chi2_light(light, Vec3(0.f), trace_environment(light), full_sphere());
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << r.describe();
    EXPECT_EQ(r.valid_fraction, 1.0);
}

TEST(EnvironmentMapLight, PdfIsPositiveWhereverRadianceIs) {
    // A direction with radiance but zero pdf would be unreachable by light sampling: biased MIS.
    EnvironmentMapLight light(make_env_image(), kEnvToWorld, kEnvScale);
    PCG32 rng(4, 4);
    int dark = 0;
    for (int k = 0; k < 100000; ++k) {
        Vec3 d = square_to_uniform_sphere(rng.next_2d());
        float pdf = light.pdf_direction(Vec3(0.f), direction_sample_from_miss(d));
        if (is_black(light.eval_environment(d))) {
            ++dark;
            continue;
        }
        ASSERT_GT(pdf, 0.f) << "direction (" << d.x << "," << d.y << "," << d.z << ")";
    }
    EXPECT_GT(dark, 0);  // the black block is seen, so the test covers both kinds of direction
}

// Maps wider than the sampling grid are sampled on merged cells whose edges do not fall on texel edges
// (1100 / 512): pdf and sampling must still agree, integrate to 1 and cover every lit texel, including a
// single bright texel.
Image make_large_env_image() {
    const int w = 1100, h = 600;
    Image img(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int ch = 0; ch < 3; ++ch)
                img.at(x, y, ch) = (x > 300 && x < 700 && y > 350 && y < 500) ? 0.f : 0.2f + 0.1f * std::sin(0.01f * float(x + ch * y));
    for (int ch = 0; ch < 3; ++ch) img.at(777, 123, ch) = 100.f;
    return img;
}

TEST(EnvironmentMapLight, LargeMapsSampleOnMergedCells) {
    EnvironmentMapLight light(make_large_env_image(), kEnvToWorld, 1.f);
    expect_samples_match_trace(light, Vec3(0.f), trace_environment(light));
    Chi2Result r = chi2_light(light, Vec3(0.f), trace_environment(light), full_sphere());
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << r.describe();
    // The bright texel's direction has a pdf far above the average (1 / 4pi): it is importance-sampled.
    Vec3 spot = light.uv_to_direction(Vec2(777.f / 1100.f, 123.5f / 599.f));
    EXPECT_GT(light.pdf_direction(Vec3(0.f), direction_sample_from_miss(spot)), 20.f * kInv4Pi);
}

TEST(EnvironmentMapLight, MitsubaOrientation) {
    // Local direction (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi)) with phi = 2 pi u,
    // theta = pi v: v = 0 is +y, v = 1 is -y, u = 0 faces -z, u = 0.25 faces +x, u = 0.5 faces +z.
    EnvironmentMapLight light(make_env_image(), Transform(), 1.f);
    auto expect_dir = [&](Vec2 uv, Vec3 expected) {
        Vec3 d = light.uv_to_direction(uv);
        EXPECT_NEAR(d.x, expected.x, 1e-6f) << "uv " << uv.x << "," << uv.y;
        EXPECT_NEAR(d.y, expected.y, 1e-6f) << "uv " << uv.x << "," << uv.y;
        EXPECT_NEAR(d.z, expected.z, 1e-6f) << "uv " << uv.x << "," << uv.y;
    };
    expect_dir({0.3f, 0.f}, Vec3(0, 1, 0));
    expect_dir({0.7f, 1.f}, Vec3(0, -1, 0));
    expect_dir({0.f, 0.5f}, Vec3(0, 0, -1));
    expect_dir({0.25f, 0.5f}, Vec3(1, 0, 0));
    expect_dir({0.5f, 0.5f}, Vec3(0, 0, 1));
    expect_dir({0.75f, 0.5f}, Vec3(-1, 0, 0));
    // to_world rotates the whole map.
    EnvironmentMapLight rotated(make_env_image(), kEnvToWorld, 1.f);
    PCG32 rng(8, 8);
    for (int k = 0; k < 100; ++k) {
        Vec2 uv = rng.next_2d();
        Vec3 a = rotated.uv_to_direction(uv), b = kEnvToWorld.vector(light.uv_to_direction(uv));
        EXPECT_LT(norm(a - b), 1e-5f);
    }
}

TEST(EnvironmentMapLight, UvDirectionRoundTrip) {
    EnvironmentMapLight light(make_env_image(), kEnvToWorld, kEnvScale);
    PCG32 rng(9, 9);
    for (int k = 0; k < 10000; ++k) {
        // Away from the poles, where u is undefined, and from the u = 0 seam, where it wraps.
        Vec2 uv(0.001f + 0.998f * rng.next_float(), 0.01f + 0.98f * rng.next_float());
        Vec2 back = light.direction_to_uv(light.uv_to_direction(uv));
        EXPECT_NEAR(back.x, uv.x, 2e-5f);
        EXPECT_NEAR(back.y, uv.y, 2e-5f);
    }
    Vec2 seam = light.direction_to_uv(light.uv_to_direction({0.f, 0.5f}));
    EXPECT_TRUE(seam.x < 1e-5f || seam.x > 1.f - 1e-5f) << seam.x;
}

TEST(EnvironmentMapLight, DirectionsAreUnitUnderAnyTransform) {
    // A rotation keeps the map's unit directions unit (they are not normalized again); a to_world with a
    // scale does not, and there they are. Lookups of a direction do not depend on its length.
    const Transform scaled = Transform::scale(Vec3(3.f, 1.f, 0.5f)) * kEnvToWorld;
    for (const Transform &t : {kEnvToWorld, scaled}) {
        EnvironmentMapLight light(make_env_image(), t, 1.f);
        PCG32 rng(10, 10);
        for (int k = 0; k < 1000; ++k) {
            const Vec2 uv(rng.next_float(), 0.01f + 0.98f * rng.next_float());
            const Vec3 d = light.uv_to_direction(uv);
            EXPECT_NEAR(norm(d), 1.f, 1e-6f);
            const Vec2 a = light.direction_to_uv(d), b = light.direction_to_uv(d * 8.f);  // a power of two: scaled exactly
            EXPECT_EQ(a.x, b.x);
            EXPECT_EQ(a.y, b.y);
        }
    }
}

TEST(EnvironmentMapLight, TexelsSitOnMitsubasGrid) {
    // Texel (i, j) is seen at u = (i + 1/2) / W (wrapping) and v = j / (H - 1) (first and last rows on
    // the poles); rows 0 and H-1 are skipped because u is undefined at the poles.
    Image img = make_env_image();
    EnvironmentMapLight light(img, kEnvToWorld, kEnvScale);
    for (int j = 1; j < kEnvH - 1; ++j)
        for (int i = 0; i < kEnvW; ++i) {
            Vec3 d = light.uv_to_direction({(float(i) + 0.5f) / kEnvW, float(j) / (kEnvH - 1)});
            Color expected = img.rgb(i, j) * kEnvScale, got = light.eval_environment(d);
            EXPECT_TRUE(near_rel(got, expected, 1e-3f, 1e-4f))
                << "texel " << i << "," << j << ": (" << got.x << "," << got.y << "," << got.z << ") vs ("
                << expected.x << "," << expected.y << "," << expected.z << ")";
        }
}

TEST(EnvironmentMapLight, LookupsBlendTheirFourTexels) {
    // Between texel centres, with unequal weights in u and v (so no two corners could trade places
    // unseen), the last column blending with the first. Maps within half's range keep half texels, those
    // beyond keep floats: both are checked, each against the image's own texels.
    for (const float gain : {1.f, 1e5f}) {
        Image img = make_env_image();
        for (float &v : img.data) v *= gain;
        EnvironmentMapLight light(img, Transform(), 1.f);
        const float fx = 0.3f, fy = 0.6f;
        for (int j = 1; j < kEnvH - 2; ++j)
            for (int i = 0; i < kEnvW; ++i) {
                const int i1 = (i + 1) % kEnvW;
                const Vec3 d = light.uv_to_direction({(float(i) + 0.5f + fx) / kEnvW, (float(j) + fy) / (kEnvH - 1)});
                const Color expected = img.rgb(i, j) * ((1 - fx) * (1 - fy)) + img.rgb(i1, j) * (fx * (1 - fy)) +
                                       img.rgb(i, j + 1) * ((1 - fx) * fy) + img.rgb(i1, j + 1) * (fx * fy);
                const Color got = light.eval_environment(d);
                EXPECT_TRUE(near_rel(got, expected, 2e-3f, 1e-4f * gain))
                    << "gain " << gain << ", between texels " << i << "," << j << ": (" << got.x << "," << got.y
                    << "," << got.z << ") vs (" << expected.x << "," << expected.y << "," << expected.z << ")";
            }
    }
}

TEST(ConstantEnvironmentLight, SamplesFollowPdf) {
    ConstantEnvironmentLight light(Color(0.7f, 0.5f, 0.2f));
    light.prepare(BBox{Vec3(-1.f), Vec3(1.f)});
    Vec3 ref(0.5f, -2.f, 1.f);
    expect_samples_match_trace(light, ref, trace_environment(light));
    Chi2Result r = chi2_light(light, ref, trace_environment(light), full_sphere());
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << r.describe();
}

TEST(PointLight, IsADeltaLight) {
    PointLight light(Vec3(1.f, 2.f, 3.f), Color(8.f));
    Color radiance;
    DirectionSample ds = light.sample_direction(Vec3(1.f, 2.f, 1.f), Vec2(0.3f, 0.6f), radiance);
    EXPECT_TRUE(ds.delta);
    EXPECT_TRUE(light.is_delta());
    EXPECT_FLOAT_EQ(ds.dist, 2.f);
    EXPECT_LT(norm(ds.d - Vec3(0, 0, 1)), 1e-6f);
    EXPECT_FLOAT_EQ(radiance.x, 2.f);  // I / r^2
    EXPECT_EQ(light.pdf_direction(Vec3(0.f), ds), 0.f);  // never hit by BSDF sampling
}

}  // namespace
}  // namespace neepp::test
