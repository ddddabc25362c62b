// The perspective camera, whole and cropped: its direction density integrates to one over the image, its
// importance is that density over cos θ, a connection lands where the ray through that image point
// starts, and a crop's pixel traces the whole film's ray to the bit.
#include <gtest/gtest.h>
#include <cmath>
#include "neepp/sampling/rng.h"
#include "neepp/scene/camera.h"

using namespace neepp;

namespace {

Camera camera(bool cropped) {
    Camera c;
    c.to_world = Transform::look_at(Vec3(1, 2, 3), Vec3(0, 0, 0), Vec3(0, 1, 0));
    c.width = 64;
    c.height = 48;
    c.fov = 50;
    if (cropped) c.crop(40, 6, 20, 30);
    c.finalize();
    return c;
}

}  // namespace

TEST(Camera, DirectionDensityIntegratesToOneOverTheImage) {
    // ∫ pdf dω over the sphere, as an integral over the plane at distance 1 (dω = cos³θ dA), with points
    // uniform over a rectangle 1.2 times the film's: pdf must be 1 / (the image's area there) inside it.
    const float tx = std::tan(25.f * kPi / 180.f) * 1.2f, ty = tx * 48.f / 64.f;
    for (bool cropped : {false, true}) {
        const Camera c = camera(cropped);
        PCG32 rng(7, 1);
        const int n = 400000;
        double sum = 0;
        for (int i = 0; i < n; ++i) {
            const Vec3 local((2 * rng.next_float() - 1) * tx, (2 * rng.next_float() - 1) * ty, 1.f);
            const Vec3 w = normalize(c.to_world.vector(local));
            const float pdf = c.pdf_direction(w);
            const float cos_theta = 1.f / norm(local);
            sum += double(pdf) * cos_theta * cos_theta * cos_theta;
            if (pdf > 0) ASSERT_NEAR(c.importance(w) * cos_theta / pdf, 1.f, 1e-4f);  // a camera ray's We cos / pdf is one
        }
        EXPECT_NEAR(sum / n * 4 * tx * ty, 1.0, 0.01) << (cropped ? "cropped" : "whole");
    }
}

TEST(Camera, AConnectionLandsWhereItsRayStarts) {
    for (bool cropped : {false, true}) {
        const Camera c = camera(cropped);
        PCG32 rng(3, 1);
        for (int i = 0; i < 1000; ++i) {
            const Vec2 u(rng.next_float(), rng.next_float());
            const Ray r = c.generate_ray(u);
            const CameraConnection k = c.connect(r.o + r.d * 5.f);
            ASSERT_TRUE(k.valid());
            EXPECT_NEAR(k.raster.x, u.x * float(c.width), 2e-3f);
            EXPECT_NEAR(k.raster.y, u.y * float(c.height), 2e-3f);
        }
    }
}

TEST(Camera, ACropsPixelTracesTheWholeFilmsRay) {
    const Camera whole = camera(false), cropped = camera(true);
    EXPECT_EQ(cropped.width, 20);
    EXPECT_EQ(cropped.height, 30);
    for (int y = 0; y < 30; ++y)
        for (int x = 0; x < 20; ++x) {
            const Vec2 j(0.25f + 0.01f * float(x), 0.7f);
            const Ray a = cropped.pixel_ray(x, y, j), b = whole.pixel_ray(x + 40, y + 6, j);
            ASSERT_TRUE(a.d.x == b.d.x && a.d.y == b.d.y && a.d.z == b.d.z && a.tmin == b.tmin) << x << "," << y;
        }
    // Outside the crop window nothing reaches the image.
    const Ray outside = whole.pixel_ray(10, 10, Vec2(0.5f, 0.5f));
    EXPECT_FALSE(cropped.connect(outside.o + outside.d * 5.f).valid());
    EXPECT_EQ(cropped.importance(outside.d), 0.f);
}

TEST(Camera, ACropOutsideTheImageIsRefused) {
    Camera c = camera(false);
    EXPECT_THROW(c.crop(60, 0, 10, 10), std::invalid_argument);
    EXPECT_THROW(c.crop(0, 0, 0, 10), std::invalid_argument);
    EXPECT_THROW(c.crop(-1, 0, 10, 10), std::invalid_argument);
    c.crop(8, 8, 16, 16);  // a crop of a crop: offsets add up
    c.crop(4, 2, 8, 8);
    EXPECT_EQ(c.crop_x, 12);
    EXPECT_EQ(c.crop_y, 10);
    EXPECT_EQ(c.film_width, 64);
}

// Orthographic: parallel rays along the view axis from the near plane, over x in [-1, 1] and y in
// [-1/aspect, 1/aspect] of camera space scaled by to_world; a crop keeps the whole film's rays; no
// importance (light paths cannot reach it).
TEST(Camera, OrthographicRaysAreParallelFromTheNearPlane) {
    Camera c;
    c.projection = Projection::Orthographic;
    c.to_world = Transform::look_at(Vec3(1, 2, 3), Vec3(1, 2, 0), Vec3(0, 1, 0)) * Transform::scale(Vec3(2, 2, 1));
    c.width = 64;
    c.height = 32;
    c.near_clip = 0.5f;
    c.far_clip = 10.f;
    c.finalize();
    const Ray centre = c.generate_ray(Vec2(0.5f, 0.5f)), corner = c.generate_ray(Vec2(0.f, 0.f));
    EXPECT_NEAR(centre.o.x, 1.f, 1e-5f);
    EXPECT_NEAR(centre.o.y, 2.f, 1e-5f);
    EXPECT_NEAR(centre.o.z, 2.5f, 1e-5f);  // the near plane, along the view direction -z
    EXPECT_NEAR(centre.d.z, -1.f, 1e-6f);
    EXPECT_EQ(centre.tmin, 0.f);
    EXPECT_NEAR(centre.tmax, 9.5f, 1e-5f);
    // Film (0,0) is the top-left, camera +x is the image's left: look_at from +z flips x to world -x...
    // ...so the top-left corner lies at world x = 1 + 2 (camera x = +1, scaled by 2, mirrored by the view).
    EXPECT_NEAR(std::abs(corner.o.x - 1.f), 2.f, 1e-5f);
    EXPECT_NEAR(corner.o.y - 2.f, 1.f, 1e-5f);  // y spans [-1/aspect, 1/aspect] = [-0.5, 0.5], times 2
    EXPECT_EQ(corner.d.x, centre.d.x);
    EXPECT_EQ(corner.d.z, centre.d.z);
    EXPECT_FALSE(c.has_importance());
    EXPECT_FALSE(c.connect(Vec3(1, 2, 0)).valid());
    EXPECT_EQ(c.importance(centre.d), 0.f);

    Camera cropped = c;
    cropped.crop(40, 6, 20, 20);
    cropped.finalize();
    const Ray a = cropped.pixel_ray(3, 4, Vec2(0.3f, 0.6f)), b = c.pixel_ray(43, 10, Vec2(0.3f, 0.6f));
    EXPECT_TRUE(a.o.x == b.o.x && a.o.y == b.o.y && a.o.z == b.o.z && a.d.z == b.d.z);
}

TEST(Camera, BadClipDistancesAreRefused) {
    Camera c;
    c.near_clip = 0.f;
    EXPECT_THROW(c.finalize(), std::invalid_argument);
    c.near_clip = 2.f;
    c.far_clip = 1.f;
    EXPECT_THROW(c.finalize(), std::invalid_argument);
}

// A thin lens: every ray of a film position passes through the point of the focal plane that the pinhole
// ray of that position meets, starts on the lens disk (the near plane along its own direction), and the
// lens centre traces the pinhole ray itself.
TEST(Camera, ThinLensRaysMeetOnTheFocalPlane) {
    Camera pin;
    pin.to_world = Transform::look_at(Vec3(1, 2, 3), Vec3(0, 0, 0), Vec3(0, 1, 0));
    pin.width = 40;
    pin.height = 30;
    pin.fov = 50.f;
    pin.finalize();
    Camera lens = pin;
    lens.aperture_radius = 0.3f;
    lens.focus_distance = 2.5f;
    lens.finalize();
    ASSERT_TRUE(lens.has_lens());
    const Vec3 view = normalize(Vec3(0, 0, 0) - Vec3(1, 2, 3));
    for (Vec2 film : {Vec2(0.5f, 0.5f), Vec2(0.1f, 0.8f), Vec2(0.93f, 0.2f)}) {
        const Ray p = pin.generate_ray(film);
        const Vec3 focus = pin.position() + p.d * (2.5f / dot(p.d, view));  // depth 2.5 along the view axis
        const Ray centre = lens.generate_ray(film, Vec2(0.5f, 0.5f));
        EXPECT_NEAR(norm(centre.d - p.d), 0.f, 1e-6f);
        for (Vec2 u : {Vec2(0.1f, 0.2f), Vec2(0.9f, 0.5f), Vec2(0.4f, 0.99f)}) {
            const Ray r = lens.generate_ray(film, u);
            const Vec3 start = r.o - pin.position();
            EXPECT_NEAR(dot(start, view), 0.f, 1e-5f);  // the lens lies in the camera's z = 0 plane...
            EXPECT_LE(norm(start), 0.3f + 1e-5f);        // ...inside its radius
            const float t = dot(focus - r.o, r.d);
            EXPECT_NEAR(norm(r.at(t) - focus), 0.f, 1e-4f);
            EXPECT_NEAR(r.tmin * dot(r.d, view), lens.near_clip, 1e-6f);  // from the near plane
        }
    }
}
