// Curves through Embree's round curves, hits completed as Mitsuba's linearcurve and bsplinecurve
// complete them: a straight segment is hit at the analytic distance with the analytic normal (cylinder,
// tangent cone, spherical end caps), no hit comes from inside a tube, a B-spline hit lies on the sweep of
// circles across its centre line with that surface's normal, and the uv runs around the tube and along the
// file's segments.
#include <gtest/gtest.h>

#include <cmath>
#include "neepp/shapes/curve_shape.h"
#include "neepp/materials/bumpmap.h"
#include "neepp/materials/diffuse.h"
#include "neepp/scene/scene.h"

using namespace neepp;

namespace {

// One curve shape; its BSDF, a flat bump map, reads tangents, so hits get dp/du, dp/dv and the frame along them.
std::unique_ptr<Scene> curve_scene(CurveBasis basis, std::vector<CurvePoint> points, std::vector<uint32_t> segments) {
    auto scene = std::make_unique<Scene>();
    auto s = std::make_unique<CurveShape>();
    s->basis = basis;
    s->points = std::move(points);
    s->segments = std::move(segments);
    s->bsdf = std::make_shared<BumpMapBSDF>(constant_texture(0.f), 1.f,
                                            std::make_shared<DiffuseBSDF>(constant_texture(Color(0.5f))));
    scene->add_shape(std::move(s));
    scene->build();
    EXPECT_TRUE(scene->shapes()[0]->tangents);
    return scene;
}

// The hit of a ray from `from` straight down (-z); fails the test when there is none.
SurfaceInteraction hit_down(const Scene &scene, Vec3 from) {
    SurfaceInteraction si;
    EXPECT_TRUE(scene.intersect(Ray{from, Vec3(0, 0, -1)}, si)) << from.x << " " << from.y;
    return si;
}

void expect_vec_near(const Vec3 &a, const Vec3 &b, float tol, const std::string &what) {
    EXPECT_NEAR(a.x, b.x, tol) << what;
    EXPECT_NEAR(a.y, b.y, tol) << what;
    EXPECT_NEAR(a.z, b.z, tol) << what;
}

TEST(Curves, StraightLinearSegmentIsHitAtTheAnalyticDistanceAndNormal) {
    const float r = 0.25f;
    auto scene = curve_scene(CurveBasis::Linear, {{{-1, 0, 0}, r}, {{1, 0, 0}, r}}, {0});
    for (float x : {-0.7f, 0.f, 0.4f})
        for (float y : {0.f, 0.1f, -0.2f}) {
            const SurfaceInteraction si = hit_down(*scene, Vec3(x, y, 5));
            const float z = std::sqrt(r * r - y * y);
            const std::string at = "x " + std::to_string(x) + ", y " + std::to_string(y);
            EXPECT_NEAR(si.t, 5 - z, 2e-5f) << at;
            expect_vec_near(si.p, Vec3(x, y, z), 2e-5f, at);
            expect_vec_near(si.n, Vec3(0, y, z) / r, 1e-4f, at);
            expect_vec_near(si.sh_frame.n, si.n, 0, at);  // Mitsuba's curves shade with the geometric normal
            // v along the segment; u around the tube from Mitsuba's frame (along +y at 0, +z at 1/4).
            EXPECT_NEAR(si.uv.y, (x + 1) / 2, 1e-4f) << at;
            EXPECT_NEAR(si.uv.x, std::atan2(z, y) / (2 * kPi), 1e-4f) << at;
            // dp/du around the tube (2 pi r long), dp/dv along it; the frame's s along dp/du.
            EXPECT_NEAR(norm(si.dpdu), 2 * kPi * r, 1e-4f) << at;
            EXPECT_NEAR(dot(si.dpdu, si.n), 0, 1e-4f) << at;
            EXPECT_NEAR(dot(si.dpdu, Vec3(1, 0, 0)), 0, 1e-4f) << at;
            expect_vec_near(si.dpdv, Vec3(2, 0, 0), 1e-4f, at);
            expect_vec_near(si.sh_frame.s, normalize(si.dpdu), 1e-4f, at);
        }
}

TEST(Curves, LinearSegmentOfChangingRadiusIsATangentConeWithSphericalEnds) {
    // From radius 0.1 at x = -1 to 0.3 at x = 1: the cone touching both spheres has its surface at
    // angle asin(0.2 / 2) to the axis; seen in the xz plane, its silhouette is -0.1 x + sqrt(0.99) z = 0.2.
    auto scene = curve_scene(CurveBasis::Linear, {{{-1, 0, 0}, 0.1f}, {{1, 0, 0}, 0.3f}}, {0});
    const float c = std::sqrt(0.99f);
    for (float x : {-0.5f, 0.f, 0.6f}) {
        const SurfaceInteraction si = hit_down(*scene, Vec3(x, 0, 5));
        EXPECT_NEAR(si.p.z, (0.2f + 0.1f * x) / c, 2e-5f) << x;
        expect_vec_near(si.n, Vec3(-0.1f, 0, c), 1e-4f, "cone at x " + std::to_string(x));
    }
    // Beyond the ends the spheres: normals from their centres.
    SurfaceInteraction si = hit_down(*scene, Vec3(1.2f, 0, 5));
    EXPECT_NEAR(si.p.z, std::sqrt(0.09f - 0.04f), 2e-5f);
    expect_vec_near(si.n, Vec3(0.2f, 0, si.p.z) / 0.3f, 1e-4f, "end cap at x = 1");
    EXPECT_NEAR(si.uv.y, 1.f, 1e-5f);
    si = hit_down(*scene, Vec3(-1.05f, 0, 5));
    EXPECT_NEAR(si.p.z, std::sqrt(0.01f - 0.0025f), 2e-5f);
    expect_vec_near(si.n, Vec3(-0.05f, 0, si.p.z) / 0.1f, 1e-4f, "end cap at x = -1");
    EXPECT_NEAR(si.uv.y, 0.f, 1e-5f);
}

TEST(Curves, NoHitFromInsideATube) {
    auto scene = curve_scene(CurveBasis::Linear, {{{-1, 0, 0}, 0.25f}, {{1, 0, 0}, 0.25f}, {{1, 2, 0}, 0.25f}}, {0, 1});
    SurfaceInteraction si;
    EXPECT_FALSE(scene->intersect(Ray{Vec3(0, 0, 0), Vec3(0, 0, 1)}, si));
    EXPECT_FALSE(scene->occluded(Ray{Vec3(0.5f, 0, 0), normalize(Vec3(0.3f, 0.2f, 1))}));
    // The same in packets (Embree calls the culling filter with several rays at once), at every width.
    std::vector<Ray> rays;
    for (int i = 0; i < 16; ++i) rays.push_back(Ray{Vec3(-0.9f + 0.1f * i, 0, 0), normalize(Vec3(0.1f, 0.2f, i % 2 ? 1.f : -1.f))});
    std::vector<const Ray *> rp;
    for (const Ray &r : rays) rp.push_back(&r);
    for (int width : {4, 8, 16}) {
        scene->set_packet_width(width);
        RayHit hits[16];
        RayHit *hp[16];
        for (int i = 0; i < 16; ++i) hp[i] = &hits[i];
        scene->trace16(rp.data(), hp, 16);
        bool occluded[16];
        scene->occluded16(rp.data(), 16, occluded);
        for (int i = 0; i < 16; ++i) {
            EXPECT_FALSE(hits[i].valid()) << "ray " << i << ", width " << width;
            EXPECT_FALSE(occluded[i]) << "ray " << i << ", width " << width;
        }
    }
    // From outside, the near side only: the ray leaving it again passes out unhit.
    si = hit_down(*scene, Vec3(0, 0, 5));
    EXPECT_NEAR(si.t, 4.75f, 2e-5f);
    EXPECT_FALSE(scene->intersect(si.spawn_ray(Vec3(0, 0, -1)), si));
}

TEST(Curves, VAlongAllSegmentsOfTheFile) {
    // Two curves, three segments: v = (segment + parameter along it) / 3.
    auto scene = curve_scene(CurveBasis::Linear,
                             {{{0, 0, 0}, 0.1f}, {{1, 0, 0}, 0.1f}, {{2, 0, 0}, 0.1f}, {{0, 1, 0}, 0.1f}, {{1, 1, 0}, 0.1f}},
                             {0, 1, 3});
    EXPECT_NEAR(hit_down(*scene, Vec3(0.25f, 0, 5)).uv.y, 0.25f / 3, 1e-4f);
    EXPECT_NEAR(hit_down(*scene, Vec3(1.5f, 0, 5)).uv.y, 1.5f / 3, 1e-4f);
    EXPECT_NEAR(hit_down(*scene, Vec3(0.75f, 1, 5)).uv.y, 2.75f / 3, 1e-4f);
    EXPECT_EQ(hit_down(*scene, Vec3(0.75f, 1, 5)).prim_index, 2u);
}

// A B-spline segment in double precision, written out independently of the renderer's: the surface
// Embree's round curves intersect is the sweep of circles of radius r(v) across the curve (each in the
// plane perpendicular to the tangent at its centre c(v)), so a point p on it is at distance r(v) from
// c(v) for the v at which p - c(v) is perpendicular to dc/dv.
struct SplineSegment {
    double p[4][3], r[4];
    explicit SplineSegment(const CurvePoint *cp) {
        for (int k = 0; k < 4; ++k) {
            p[k][0] = cp[k].p.x, p[k][1] = cp[k].p.y, p[k][2] = cp[k].p.z;
            r[k] = cp[k].radius;
        }
    }
    // Weights of the four points (d-th derivative) at v: the uniform cubic B-spline's basis matrix.
    static void weights(double v, int d, double w[4]) {
        static const double m[4][4] = {{1, 4, 1, 0}, {-3, 0, 3, 0}, {3, -6, 3, 0}, {-1, 3, -3, 1}};  // rows: 1, v, v^2, v^3
        const double powers[3][4] = {{1, v, v * v, v * v * v}, {0, 1, 2 * v, 3 * v * v}, {0, 0, 2, 6 * v}};
        for (int k = 0; k < 4; ++k) {
            w[k] = 0;
            for (int i = 0; i < 4; ++i) w[k] += powers[d][i] * m[i][k] / 6;
        }
    }
    void eval(double v, int d, double out[3], double &radius) const {
        double w[4];
        weights(v, d, w);
        out[0] = out[1] = out[2] = radius = 0;
        for (int k = 0; k < 4; ++k) {
            for (int i = 0; i < 3; ++i) out[i] += w[k] * p[k][i];
            radius += w[k] * r[k];
        }
    }
    // |q - c(v)| - r(v) at the v near v0 where q - c(v) is perpendicular to the curve (Newton's method).
    double offset(const double q[3], double v0, double *v_out = nullptr) const {
        double v = v0, c[3], dc[3], dcc[3], r0, r1, r2;
        for (int it = 0; it < 50; ++it) {
            eval(v, 0, c, r0), eval(v, 1, dc, r1), eval(v, 2, dcc, r2);
            double g = 0, dg = 0;
            for (int i = 0; i < 3; ++i) g += (q[i] - c[i]) * dc[i], dg += (q[i] - c[i]) * dcc[i] - dc[i] * dc[i];
            v -= g / dg;
        }
        eval(v, 0, c, r0);
        if (v_out) *v_out = v;
        return std::sqrt((q[0] - c[0]) * (q[0] - c[0]) + (q[1] - c[1]) * (q[1] - c[1]) + (q[2] - c[2]) * (q[2] - c[2])) - r0;
    }
};

TEST(Curves, BSplineHitsLieAtTheirRadiusFromTheCurveWithTheSurfaceNormal) {
    // A zigzag in the xy plane (Mitsuba's documentation curve), first of constant radius, then of a radius
    // that grows along it; rays straight down onto it from above a grid that stays clear of its open ends.
    for (bool growing : {false, true}) {
        std::vector<CurvePoint> points;
        const float xs[7] = {-1, -0.5f, -0.25f, 0, 0.25f, 0.5f, 1}, ys[7] = {-1, 1, -1, 1, -1, 1, -1};
        for (int i = 0; i < 7; ++i) points.push_back({{xs[i], ys[i] * 0.5f, 0}, growing ? 0.04f + 0.02f * i : 0.1f});
        auto scene = curve_scene(CurveBasis::BSpline, points, {0, 1, 2, 3});
        int hits = 0;
        for (int i = 0; i < 30; ++i)
            for (int j = 0; j < 30; ++j) {
                const Vec3 from(-0.4f + 0.8f * (i + 0.5f) / 30, -0.6f + 1.2f * (j + 0.5f) / 30, 5);
                SurfaceInteraction si;
                if (!scene->intersect(Ray{from, Vec3(0, 0, -1)}, si)) continue;
                ++hits;
                const std::string at = std::string(growing ? "growing" : "constant") + " radius, ray at " +
                                       std::to_string(from.x) + " " + std::to_string(from.y);
                const SplineSegment seg(&points[si.prim_index]);
                const double v_hit = si.uv.y * 4 - si.prim_index;  // Embree's parameter along the segment
                const double q[3] = {si.p.x, si.p.y, si.p.z};
                double v;
                EXPECT_NEAR(seg.offset(q, v_hit, &v), 0, 1e-5) << at;
                EXPECT_NEAR(v, v_hit, 1e-3) << at;
                // The normal: the gradient of that offset at p, by central differences.
                double grad[3];
                for (int k = 0; k < 3; ++k) {
                    double a[3] = {q[0], q[1], q[2]}, b[3] = {q[0], q[1], q[2]};
                    a[k] += 1e-5, b[k] -= 1e-5;
                    grad[k] = (seg.offset(a, v) - seg.offset(b, v)) / 2e-5;
                }
                expect_vec_near(si.n, normalize(Vec3(float(grad[0]), float(grad[1]), float(grad[2]))), 2e-3f, at);
                EXPECT_LT(dot(si.n, Vec3(0, 0, -1)), 0) << at;
                EXPECT_NEAR(dot(si.dpdu, si.n), 0, 1e-3f * norm(si.dpdu)) << at;
                EXPECT_GE(si.uv.x, 0.f);
                EXPECT_LT(si.uv.x, 1.f);
            }
        EXPECT_GT(hits, 100) << "the curve covers too little of the grid for the test to mean much";
    }
}

}  // namespace
