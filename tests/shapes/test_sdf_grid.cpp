// The sdfgrid shape through Embree: a grid holding a sphere's distance is hit where the sphere is, with
// its normal (single rays and packets, intersection and occlusion, from outside and from inside), missed
// beside it, hit and missed by rays grazing it and along grid planes, and left by the rays spawned from
// its hits; a plane is hit exactly; Mitsuba 3's own hits on an irregular grid (sdf_grid_reference.inc)
// are reproduced; and the grids Mitsuba refuses are refused.
#include <gtest/gtest.h>

#include <memory>
#include "common/volume_grid_writer.h"
#include "neepp/math/frame.h"
#include "neepp/math/warp.h"
#include "neepp/sampling/rng.h"
#include "neepp/scene/scene.h"
#include "neepp/shapes/sdf_grid_shape.h"

using namespace neepp;

namespace {

struct SdfRayReference {
    Vec3 o, d;
    bool hit;
    float t;
    Vec3 n, smooth_n, analytic_n;
};
#include "sdf_grid_reference.inc"

std::shared_ptr<const SdfGrid> sphere_grid(int n, SdfGrid::Normals normals = SdfGrid::Normals::Smooth) {
    auto g = neepp::testing::sphere_sdf_grid(n);
    return std::make_shared<const SdfGrid>(n, n, n, std::move(g.values), normals);
}

std::unique_ptr<Scene> sdf_scene(std::shared_ptr<const SdfGrid> grid, const Transform &to_world) {
    auto scene = std::make_unique<Scene>();
    auto s = std::make_unique<SdfGridShape>();
    s->grid = std::move(grid);
    s->to_world = to_world;
    scene->add_shape(std::move(s));
    scene->build();
    return scene;
}

// The grid's sphere (centre 0.5, radius 0.3) moved by a rotation, a uniform scale of 2 and a translation.
const Transform kToWorld = Transform::translate({1, -2, 0.5f}) * Transform::rotate({1, 1, 0}, 30) * Transform::scale(Vec3(2));
struct Sphere {
    Vec3 c = kToWorld.point(Vec3(0.5f));
    float r = 0.6f;
    // The first t >= 0 at which the ray meets it, or -1.
    float hit(const Ray &ray) const {
        const Vec3 oc = ray.o - c;
        const float b = dot(oc, ray.d), disc = b * b - (dot(oc, oc) - r * r);
        if (disc < 0) return -1;
        const float near = -b - std::sqrt(disc), far = -b + std::sqrt(disc);
        return near >= 0 ? near : far >= 0 ? far : -1;
    }
    // The distance from the centre to the ray's line.
    float miss_distance(const Ray &ray) const {
        const Vec3 oc = c - ray.o;
        return norm(oc - ray.d * dot(oc, ray.d));
    }
};

// A ray from 5 radii away in a random direction toward a random point within `spread` radii of the centre.
Ray ray_toward(const Sphere &s, PCG32 &rng, float spread) {
    const Vec3 o = s.c + square_to_uniform_sphere(rng.next_2d()) * (5 * s.r);
    const Vec3 target = s.c + square_to_uniform_sphere(rng.next_2d()) * (spread * s.r * rng.next_float());
    return Ray{o, normalize(target - o)};
}

}  // namespace

TEST(SdfGrid, HitsTheSphereItHoldsAtItsDistanceWithItsNormal) {
    const Sphere sphere;
    for (SdfGrid::Normals normals : {SdfGrid::Normals::Smooth, SdfGrid::Normals::Analytic}) {
        auto scene = sdf_scene(sphere_grid(41, normals), kToWorld);
        const auto &shape = dynamic_cast<const SdfGridShape &>(*scene->shapes()[0]);
        PCG32 rng;
        rng.seed(1, 2);
        for (int i = 0; i < 500; ++i) {
            const Ray ray = ray_toward(sphere, rng, 0.7f);
            const RayHit hit = scene->trace(ray);
            ASSERT_TRUE(hit.valid()) << i;
            // The interpolated sphere is within about 1e-3 of the true one (a voxel is 0.05 across here).
            EXPECT_NEAR(hit.t, sphere.hit(ray), 3e-3f) << i;
            SurfaceInteraction si;
            scene->fill(hit, ray, si);
            EXPECT_EQ(si.shape, &shape);
            EXPECT_NEAR(norm(si.p - ray.at(hit.t)), 0.f, 1e-5f);
            const Vec3 exact = normalize(si.p - sphere.c);
            EXPECT_GT(dot(si.n, exact), 0.998f) << i;
            EXPECT_GT(dot(si.sh_frame.n, exact), 0.998f) << i;
            EXPECT_NEAR(norm(si.n), 1.f, 1e-5f);
            EXPECT_NEAR(norm(si.sh_frame.n), 1.f, 1e-5f);
            // The voxel's box, which Embree culls by, holds the hit.
            const BBox &box = shape.grid->surface_bounds(hit.prim);
            EXPECT_TRUE(box.contains(shape.to_object().point(si.p))) << i;
            EXPECT_TRUE(scene->occluded(ray));
        }
    }
}

TEST(SdfGrid, RaysFromInsideHitItLeavingWithTheNormalOutward) {
    const Sphere sphere;
    auto scene = sdf_scene(sphere_grid(41), kToWorld);
    PCG32 rng;
    rng.seed(3, 4);
    for (int i = 0; i < 300; ++i) {
        const Ray ray{sphere.c + square_to_uniform_sphere(rng.next_2d()) * (0.5f * sphere.r * rng.next_float()),
                      square_to_uniform_sphere(rng.next_2d())};
        SurfaceInteraction si;
        ASSERT_TRUE(scene->intersect(ray, si)) << i;
        EXPECT_NEAR(si.t, sphere.hit(ray), 3e-3f) << i;
        EXPECT_GT(dot(si.n, ray.d), 0.5f) << i;
        EXPECT_TRUE(scene->occluded(ray));
    }
}

TEST(SdfGrid, RaysBesideItOrAwayFromItMissIt) {
    const Sphere sphere;
    auto scene = sdf_scene(sphere_grid(41), kToWorld);
    PCG32 rng;
    rng.seed(5, 6);
    int beside = 0;
    for (int i = 0; i < 400; ++i) {
        Ray ray = ray_toward(sphere, rng, 3.f);
        if (i % 4 == 0) ray.d = normalize(ray.o - sphere.c);  // straight away from it
        if (sphere.hit(ray) >= 0 && sphere.miss_distance(ray) < 1.02f * sphere.r) continue;
        ++beside;
        EXPECT_FALSE(scene->trace(ray).valid()) << i;
        EXPECT_FALSE(scene->occluded(ray)) << i;
    }
    EXPECT_GT(beside, 200);
}

TEST(SdfGrid, GrazingRaysHitInsideItsRimAndMissOutside) {
    const Sphere sphere;
    auto scene = sdf_scene(sphere_grid(41), kToWorld);
    PCG32 rng;
    rng.seed(7, 8);
    for (int i = 0; i < 300; ++i) {
        // A ray from far away whose line passes at 0.98 or 1.02 radii from the centre.
        const Vec3 toward = square_to_uniform_sphere(rng.next_2d());
        const Vec3 side = Frame(toward).to_world(Vec3(std::cos(float(i)), std::sin(float(i)), 0));
        const float offset = (i % 2 ? 1.02f : 0.98f) * sphere.r;
        const Ray ray{sphere.c - toward * (5 * sphere.r) + side * offset, toward};
        const RayHit hit = scene->trace(ray);
        if (i % 2) {
            EXPECT_FALSE(hit.valid()) << i;
            EXPECT_FALSE(scene->occluded(ray)) << i;
        } else {
            ASSERT_TRUE(hit.valid()) << i;
            // Where the rim is shallow, a small radial error is a larger one along the ray.
            EXPECT_NEAR(hit.t, sphere.hit(ray), 2e-2f) << i;
        }
    }
}

TEST(SdfGrid, RaysAlongGridPlanesMeetItWhereTheGridHoldsZero) {
    // Untransformed, 41 points a side: the sphere's poles (0.5 +- 0.3) are grid points, where the grid holds
    // the distance exactly, and the rays run in grid planes (two direction components 0).
    auto scene = sdf_scene(sphere_grid(41, SdfGrid::Normals::Analytic), Transform());
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.f, -1.f}) {
            Vec3 o(0.5f), d(0.f);
            o[axis] = 0.5f - 1.5f * sign;
            d[axis] = sign;
            SurfaceInteraction si;
            ASSERT_TRUE(scene->intersect(Ray{o, d}, si)) << axis;
            EXPECT_NEAR(si.t, 1.2f, 1e-5f) << axis;
            // The pole lies on voxel faces; its normal is the gradient of the voxels above it in the other
            // two axes (as Mitsuba's), tilted by their slope.
            EXPECT_NEAR(dot(si.n, -d), 1.f, 3e-3f) << axis;
        }
    // Along a voxel's edge (x and y on grid lines 0.45 = 18 / 40 and 0.55 = 22 / 40).
    SurfaceInteraction si;
    ASSERT_TRUE(scene->intersect(Ray{{0.45f, 0.55f, -1.f}, {0, 0, 1}}, si));
    EXPECT_NEAR(si.t, 1.f + 0.5f - std::sqrt(0.09f - 0.005f), 2e-3f);
}

TEST(SdfGrid, APlaneIsHitExactlyWithItsNormal) {
    // f = x - 0.3 is trilinear, so the interpolant is the plane itself and both normals are exactly +x.
    const int n = 5;
    std::vector<float> values;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) values.push_back(float(x) / float(n - 1) - 0.3f);
    for (SdfGrid::Normals normals : {SdfGrid::Normals::Smooth, SdfGrid::Normals::Analytic}) {
        auto scene = sdf_scene(std::make_shared<const SdfGrid>(n, n, n, values, normals), Transform());
        PCG32 rng;
        rng.seed(9, normals == SdfGrid::Normals::Smooth);
        for (int i = 0; i < 100; ++i) {
            const Vec3 o(-1.f, 0.1f + 0.8f * rng.next_float(), 0.1f + 0.8f * rng.next_float());
            const Vec3 target(0.3f, 0.1f + 0.8f * rng.next_float(), 0.1f + 0.8f * rng.next_float());
            const Ray ray{o, normalize(target - o)};
            SurfaceInteraction si;
            ASSERT_TRUE(scene->intersect(ray, si)) << i;
            EXPECT_NEAR(si.p.x, 0.3f, 1e-6f) << i;
            EXPECT_NEAR(si.n.x, 1.f, 1e-6f) << i;
            EXPECT_NEAR(si.sh_frame.n.x, 1.f, 1e-6f) << i;
        }
    }
}

TEST(SdfGrid, ShadowRaysStopAtTheirEndAndRaysLeavingAHitDoNotMeetItAgain) {
    const Sphere sphere;
    auto scene = sdf_scene(sphere_grid(41), kToWorld);
    PCG32 rng;
    rng.seed(11, 12);
    for (int i = 0; i < 300; ++i) {
        Ray ray = ray_toward(sphere, rng, 0.7f);
        const float t = sphere.hit(ray);
        ray.tmax = t - 0.01f;
        EXPECT_FALSE(scene->occluded(ray)) << i;
        EXPECT_FALSE(scene->trace(ray).valid()) << i;
        ray.tmax = t + 0.01f;
        EXPECT_TRUE(scene->occluded(ray)) << i;
        SurfaceInteraction si;
        ASSERT_TRUE(scene->intersect(ray, si)) << i;
        // Outward, a convex shape is not met again; inward, it is met on its far side.
        const Vec3 out = Frame(si.n).to_world(square_to_cosine_hemisphere(rng.next_2d()));
        EXPECT_FALSE(scene->occluded(si.spawn_ray(out))) << i;
        SurfaceInteraction far;
        ASSERT_TRUE(scene->intersect(si.spawn_ray(-out), far)) << i;
        EXPECT_GT(far.t, 0.05f * sphere.r) << i;
    }
}

TEST(SdfGrid, PacketsFindTheSameHitsAsSingleRays) {
    const Sphere sphere;
    auto scene = sdf_scene(sphere_grid(21), kToWorld);
    PCG32 rng;
    rng.seed(13, 14);
    int hits = 0;
    for (int width : {16, 8, 4}) {
        scene->set_packet_width(width);
        for (int round = 0; round < 50; ++round) {
            const int n = round % 2 ? 16 : 11;
            Ray rays[16];
            RayHit packet[16];
            const Ray *rp[16];
            RayHit *hp[16];
            for (int i = 0; i < n; ++i) {
                rays[i] = ray_toward(sphere, rng, 2.f);
                if (i % 3 == 0) rays[i].tmax = 5 * sphere.r;
                rp[i] = &rays[i], hp[i] = &packet[i];
            }
            scene->trace16(rp, hp, n);
            bool occluded[16];
            scene->occluded16(rp, n, occluded);
            for (int i = 0; i < n; ++i) {
                const RayHit single = scene->trace(rays[i]);
                ASSERT_EQ(single.valid(), packet[i].valid()) << width << " " << i;
                EXPECT_EQ(occluded[i], single.valid()) << width << " " << i;
                if (!single.valid()) continue;
                ++hits;
                EXPECT_EQ(single.t, packet[i].t);
                EXPECT_EQ(single.prim, packet[i].prim);
            }
        }
    }
    EXPECT_GT(hits, 300);
}

TEST(SdfGrid, MitsubasOwnHitsAreReproduced) {
    const std::vector<float> values(std::begin(kReferenceGridValues), std::end(kReferenceGridValues));
    const Transform to_world = Transform::translate(kReferenceTranslate) * Transform::scale(kReferenceScale);
    const uint32_t *size = kReferenceGridSize;
    auto smooth = sdf_scene(std::make_shared<const SdfGrid>(size[0], size[1], size[2], values), to_world);
    auto analytic = sdf_scene(std::make_shared<const SdfGrid>(size[0], size[1], size[2], values, SdfGrid::Normals::Analytic),
                              to_world);
    int hits = 0;
    for (const SdfRayReference &r : kReferenceRays) {
        const Ray ray{r.o, r.d};
        SurfaceInteraction s, a;
        ASSERT_EQ(smooth->intersect(ray, s), r.hit) << r.o.x << " " << r.o.y << " " << r.o.z;
        ASSERT_EQ(analytic->intersect(ray, a), r.hit);
        if (!r.hit) continue;
        ++hits;
        // Mitsuba stops its root search within 1e-5 of the root.
        EXPECT_NEAR(s.t, r.t, 2e-5f * (1 + r.t));
        for (int k = 0; k < 3; ++k) {
            EXPECT_NEAR(s.n[k], r.n[k], 1e-4f) << hits;
            EXPECT_NEAR(s.sh_frame.n[k], r.smooth_n[k], 1e-4f) << hits;
            EXPECT_NEAR(a.sh_frame.n[k], r.analytic_n[k], 1e-4f) << hits;
        }
    }
    EXPECT_GT(hits, 30);
}

TEST(SdfGrid, GridsWithoutSurfaceOrWithBadValuesAreRefused) {
    auto refused = [](uint32_t nx, uint32_t ny, uint32_t nz, std::vector<float> values, const std::string &needle) {
        try {
            SdfGrid grid(nx, ny, nz, std::move(values));
            ADD_FAILURE() << "expected an error containing \"" << needle << "\"";
        } catch (const std::invalid_argument &e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    refused(1, 2, 2, std::vector<float>(4, -1.f), "at least 2 points");
    refused(2, 2, 2, std::vector<float>(7, -1.f), "needs as many values");
    refused(2, 2, 2, std::vector<float>(8, 1.f), "no surface");
    refused(2, 2, 2, std::vector<float>(8, -1.f), "no surface");
    std::vector<float> nan(8, 1.f);
    nan[5] = std::nanf("");
    refused(2, 2, 2, nan, "(1, 0, 1) is not finite");
    // A corner at exactly 0 is surface, as in Mitsuba.
    std::vector<float> touching(8, 1.f);
    touching[3] = 0.f;
    EXPECT_EQ(SdfGrid(2, 2, 2, touching).voxel_count(), 1u);
}
