// Light samples in lanes (LightSampleLanes) against AreaLight::sample_direction, one at a time: the same
// point, direction, distance, density and radiance for every lane count and mix of lights, and which
// lights take the lane path at all.
#include <gtest/gtest.h>

#include <random>

#include "neepp/shapes/sphere.h"
#include "neepp/shapes/triangle_mesh.h"
#include "neepp/lights/area_light.h"
#include "neepp/lights/light_lanes.h"
#include "neepp/textures/checkerboard_texture.h"

namespace neepp::test {
namespace {

// A parallelogram from corner c and edges e1, e2 (two triangles, as Mitsuba's rectangle), flipped if asked.
TriangleMesh make_parallelogram(Vec3 c, Vec3 e1, Vec3 e2, bool flip) {
    TriangleMesh s;
    s.positions = {c, c + e1, c + e1 + e2, c + e2};
    s.indices = {0, 1, 2, 0, 2, 3};
    s.flip_normals = flip;
    s.finalize();
    return s;
}

void expect_near(const Vec3 &a, const Vec3 &b, float tol, const char *what) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], tol * std::max(1.f, std::abs(b[k]))) << what << "[" << k << "]";
}

TEST(LightLanes, SameSamplesAsOneAtATime) {
    if (!LightSampleLanes::kEnabled) GTEST_SKIP() << "no AVX: lights are sampled one at a time";
    // Two lights of different size, tilt, radiance and side, mixed in the same lanes; no edge has a zero
    // coordinate, so that each of u and v moves every coordinate of the point.
    TriangleMesh a = make_parallelogram(Vec3(-1.f, 2.f, -0.5f), Vec3(2.f, 0.4f, -0.3f), Vec3(0.2f, 0.3f, 1.f), false);
    TriangleMesh b = make_parallelogram(Vec3(0.5f, -1.f, 1.f), Vec3(-0.1f, 0.5f, 0.3f), Vec3(0.2f, 0.25f, -0.7f), true);
    AreaLight la(&a, constant_texture(Color(3.f, 2.f, 1.f))), lb(&b, constant_texture(Color(0.5f, 7.f, 0.25f)));
    const BBox bounds{Vec3(-5.f), Vec3(5.f)};
    la.prepare(bounds), lb.prepare(bounds);
    ASSERT_NE(la.lane_record(), nullptr);
    ASSERT_NE(lb.lane_record(), nullptr);
    const AreaLight *lights[2] = {&la, &lb};

    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u01(0.f, 1.f), box(-3.f, 3.f);
    int valid = 0, invalid = 0;
    for (int count = 1; count <= 2 * LightSampleLanes::kLanes + 3; ++count) {  // partial and several fills
        for (int round = 0; round < 40; ++round) {
            struct Case { const AreaLight *light; Vec3 ref; Vec2 u; };
            std::vector<Case> cases(count);
            std::vector<LightSample> out(count);
            LightSampleLanes lanes;
            for (int i = 0; i < count; ++i) {
                cases[i] = {lights[rng() % 2], Vec3(box(rng), box(rng), box(rng)), Vec2(u01(rng), u01(rng))};
                lanes.add(*cases[i].light->lane_record(), cases[i].ref, cases[i].u, out[i]);
            }
            lanes.flush();
            for (int i = 0; i < count; ++i) {
                Color radiance;
                const DirectionSample want = cases[i].light->sample_direction(cases[i].ref, cases[i].u, radiance);
                const DirectionSample &got = out[i].ds;
                expect_near(got.p, want.p, 1e-5f, "p");
                expect_near(got.n, want.n, 0.f, "n");
                expect_near(got.ns, want.ns, 0.f, "ns");
                expect_near(got.d, want.d, 1e-5f, "d");
                EXPECT_NEAR(got.dist, want.dist, 1e-5f * want.dist);
                EXPECT_FALSE(got.delta);
                // Validity agrees (away from the light's plane, where rounding could tip it) ...
                const float cos_light = std::abs(dot(want.n, want.d));
                if (cos_light > 1e-4f) {
                    ASSERT_EQ(got.pdf > 0, want.pdf > 0) << "lane " << i << " of " << count;
                }
                // ... and so do the density and radiance of a valid sample; an invalid one carries neither.
                if (want.pdf > 0 && got.pdf > 0) {
                    EXPECT_NEAR(got.pdf, want.pdf, 1e-4f * want.pdf);
                    EXPECT_EQ(out[i].radiance, radiance);
                    ++valid;
                } else if (!(got.pdf > 0)) {
                    EXPECT_EQ(got.pdf, 0.f);
                    EXPECT_EQ(out[i].radiance, Color(0.f));
                    ++invalid;
                }
            }
        }
    }
    // Both kinds were exercised in numbers (a quarter to three quarters of the box sees a light's front).
    EXPECT_GT(valid, 1000);
    EXPECT_GT(invalid, 1000);
}

TEST(LightLanes, PointOnTheLightIsInvalid) {
    if (!LightSampleLanes::kEnabled) GTEST_SKIP() << "no AVX: lights are sampled one at a time";
    TriangleMesh s = make_parallelogram(Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), false);
    AreaLight light(&s, constant_texture(1.f));
    light.prepare(BBox{Vec3(-1.f), Vec3(1.f)});
    LightSample out;
    LightSampleLanes lanes;
    lanes.add(*light.lane_record(), Vec3(0.f), Vec2(0.f, 0.f), out);  // the sampled point is the reference point
    lanes.flush();
    EXPECT_EQ(out.ds.pdf, 0.f);
    EXPECT_EQ(out.radiance, Color(0.f));
}

TEST(LightLanes, OnlyConstantParallelogramsTakeLanes) {
    const BBox bounds{Vec3(-1.f), Vec3(1.f)};
    TriangleMesh quad = make_parallelogram(Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), false);
    // Textured radiance needs the sampled point's uv and a lookup: one at a time.
    AreaLight textured(&quad, std::make_shared<CheckerboardTexture>(constant_texture(1.f), constant_texture(0.f),
                                                                   Transform::scale(Vec3(4.f))));
    textured.prepare(bounds);
    EXPECT_EQ(textured.lane_record(), nullptr);
    // A mesh that is not a parallelogram chooses a triangle first.
    TriangleMesh triangle;
    triangle.positions = {Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f)};
    triangle.indices = {0, 1, 2};
    triangle.finalize();
    AreaLight on_triangle(&triangle, constant_texture(1.f));
    on_triangle.prepare(bounds);
    EXPECT_EQ(on_triangle.lane_record(), nullptr);
    // A sphere.
    Sphere sphere;
    sphere.radius = 1.f;
    sphere.finalize();
    AreaLight on_sphere(&sphere, constant_texture(1.f));
    on_sphere.prepare(bounds);
    EXPECT_EQ(on_sphere.lane_record(), nullptr);
    // Before prepare(), nothing is known of the shape: one at a time.
    AreaLight unprepared(&quad, constant_texture(1.f));
    EXPECT_EQ(unprepared.lane_record(), nullptr);
}

}  // namespace
}  // namespace neepp::test
