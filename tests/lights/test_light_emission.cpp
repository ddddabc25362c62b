// Emission sampling (light paths of BDPT and light tracing): each light's emitted rays follow the densities
// pdf_emission reports for them (chi-square over directions, and the round trip on every sample), and
// carry the light's flux (E[Le |cos| / (pdf_pos pdf_dir)] is the emitted power).
#include <gtest/gtest.h>
#include "common/chi2.h"
#include "neepp/shapes/sphere.h"
#include "neepp/base/texture.h"
#include "neepp/lights/area_light.h"
#include "neepp/lights/directional_light.h"
#include "neepp/lights/environment_light.h"
#include "neepp/lights/projector_light.h"
#include "neepp/lights/spot_light.h"
#include "neepp/textures/bitmap_texture.h"
#include "neepp/math/frame.h"
#include "neepp/sampling/rng.h"

using namespace neepp;
using namespace neepp::test;

namespace {

Sphere make_sphere(bool flip) {
    Sphere s;
    s.center = Vec3(0.3f, -0.2f, 1.f);
    s.radius = 0.7f;
    s.flip_normals = flip;
    s.finalize();
    return s;
}

Image make_sky() {
    Image img(16, 8, 3);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y, c) = (x == 3 && y == 2) ? 30.f : 0.2f + 0.05f * float(x % 5 + c);
    return img;
}

void expect_round_trip(const Light &light, int n = 20000) {
    PCG32 rng(7, 11);
    int valid = 0;
    for (int i = 0; i < n; ++i) {
        const EmissionSample es = light.sample_emission(rng.next_2d(), rng.next_2d());
        if (!es.valid()) continue;
        ++valid;
        const EmissionDensity d = light.pdf_emission(es.p, es.n, es.ns, es.ray.d);
        ASSERT_NEAR(d.pos, es.pdf_pos, 1e-5f * es.pdf_pos);
        ASSERT_NEAR(d.dir, es.pdf_dir, 2e-3f * es.pdf_dir);
        ASSERT_NEAR(norm(es.ray.d), 1.f, 1e-5f);
    }
    EXPECT_GT(valid, n * 9 / 10);
}

// Directions emitted from one fixed origin (u_pos held), against pdf_emission's direction density there.
// ires: each cell's pdf integral from ires x ires points (more where the density has edges across cells).
Chi2Result chi2_directions(const Light &light, Vec2 u_pos, int ires = 8) {
    const EmissionSample at = light.sample_emission(u_pos, Vec2(0.5f, 0.5f));
    SphereChi2Config cfg;
    cfg.res = 40;
    cfg.ires = ires;
    cfg.sample_count = 300000;
    return chi2_sphere_test(
        [&](PCG32 &rng) -> std::optional<Vec3> {
            const EmissionSample es = light.sample_emission(u_pos, rng.next_2d());
            if (!es.valid()) return std::nullopt;
            return es.ray.d;
        },
        [&](const Vec3 &w) { return double(light.pdf_emission(at.p, at.n, at.ns, w).dir); }, cfg);
}

// E[Le |cos theta| / (pdf_pos pdf_dir)] over emitted rays: the light's flux.
double mean_flux(const Light &light, int n = 400000) {
    PCG32 rng(3, 5);
    double sum = 0;
    for (int i = 0; i < n; ++i) {
        const EmissionSample es = light.sample_emission(rng.next_2d(), rng.next_2d());
        if (!es.valid()) continue;
        const float cos = (es.n.x == 0 && es.n.y == 0 && es.n.z == 0) ? 1.f : std::abs(dot(es.n, es.ray.d));
        sum += luminance(es.radiance) * cos / (es.pdf_pos * es.pdf_dir);
    }
    return sum / n;
}

TEST(LightEmission, AreaLightRaysFollowTheirDensities) {
    for (bool flip : {false, true}) {
        Sphere shape = make_sphere(flip);
        AreaLight light(&shape, constant_texture(Color(2.f, 1.f, 0.5f)));
        light.prepare(shape.bounds());
        expect_round_trip(light);
        for (Vec2 u : {Vec2(0.2f, 0.7f), Vec2(0.9f, 0.1f)}) {
            const Chi2Result r = chi2_directions(light, u);
            ASSERT_TRUE(r.error.empty()) << r.describe();
            EXPECT_GT(r.p_value, 1e-4) << r.describe();
            EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << r.describe();
        }
        // The power a light sampler weighs it by: pi · area · Le.
        EXPECT_NEAR(mean_flux(light), luminance(light.power()), 1e-2 * luminance(light.power()));
        // Emitted from the side that emits: outward unless the normals are flipped.
        PCG32 rng(1, 2);
        for (int i = 0; i < 200; ++i) {
            const EmissionSample es = light.sample_emission(rng.next_2d(), rng.next_2d());
            EXPECT_EQ(dot(es.ray.d, es.p - shape.center) > 0, !flip);
        }
    }
}

TEST(LightEmission, EnvironmentRaysComeFromADiskAcrossTheScene) {
    const BBox bounds{Vec3(-1.f, 0.f, -2.f), Vec3(3.f, 1.f, 0.f)};
    const SceneSphere sphere(bounds);
    EnvironmentMapLight env(make_sky(), Transform::rotate(Vec3(0.f, 1.f, 0.3f), 25.f), 1.5f);
    ConstantEnvironmentLight constant(Color(0.5f));
    for (Light *light : {static_cast<Light *>(&env), static_cast<Light *>(&constant)}) {
        light->prepare(bounds);
        expect_round_trip(*light);
        const Chi2Result r = chi2_directions(*light, Vec2(0.3f, 0.6f));
        ASSERT_TRUE(r.error.empty()) << r.describe();
        EXPECT_GT(r.p_value, 1e-4) << r.describe();
        // Every ray starts outside the bounding sphere, aimed so it crosses the disk through the centre
        // perpendicular to it at most a radius from the centre: the whole scene is reached.
        PCG32 rng(5, 6);
        for (int i = 0; i < 500; ++i) {
            const EmissionSample es = light->sample_emission(rng.next_2d(), rng.next_2d());
            ASSERT_GT(norm(es.ray.o - sphere.center), sphere.radius);
            const Vec3 to_center = sphere.center - es.ray.o;
            const Vec3 across = to_center - es.ray.d * dot(to_center, es.ray.d);
            EXPECT_LE(norm(across), sphere.radius * (1 + 1e-4f));
            EXPECT_GT(dot(to_center, es.ray.d), 0.f);
        }
    }
    // A constant environment's flux through the disk: L · 4 pi · pi r².
    EXPECT_NEAR(mean_flux(constant), 0.5 * 4 * kPi * kPi * sphere.radius * sphere.radius,
                1e-3 * 0.5 * 4 * kPi * kPi * sphere.radius * sphere.radius);
}

TEST(LightEmission, PointLightEmitsItsIntensityEverywhere) {
    PointLight light(Vec3(1.f, 2.f, 3.f), Color(4.f));
    expect_round_trip(light);
    const Chi2Result r = chi2_directions(light, Vec2(0.5f, 0.5f));
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
    EXPECT_NEAR(mean_flux(light), luminance(light.power()), 1e-4 * luminance(light.power()));
}

}  // namespace

namespace {

SpotLight tilted_spot(float cutoff, float beam) {
    return SpotLight(Transform::look_at(Vec3(0.5f, 2.f, -1.f), Vec3(0.2f, 0.f, 0.3f), Vec3(0, 1, 0)), Color(3.f, 2.f, 1.f),
                     cutoff, beam);
}

}  // namespace

// Mitsuba's spot: its rays fill the cone uniformly (chi-square), carry intensity × falloff, and add up to
// the power it reports (intensity × ∫ falloff dω).
TEST(LightEmission, SpotLightEmitsIntoItsConeWithItsFalloff) {
    for (auto [cutoff, beam] : {std::pair{20.f, 15.f}, std::pair{60.f, 10.f}, std::pair{170.f, 0.f}}) {
        const SpotLight light = tilted_spot(cutoff, beam);
        expect_round_trip(light);
        const Chi2Result r = chi2_directions(light, Vec2(0.5f, 0.5f));
        ASSERT_TRUE(r.error.empty()) << r.describe();
        EXPECT_GT(r.p_value, 1e-4) << r.describe();
        EXPECT_NEAR(mean_flux(light), luminance(light.power()), 2e-3 * luminance(light.power())) << cutoff;
    }
    // The falloff: full within beam_width, linear in the angle to zero at cutoff_angle.
    const SpotLight light = tilted_spot(20.f, 10.f);
    const Vec3 axis = normalize(Vec3(0.2f, 0.f, 0.3f) - Vec3(0.5f, 2.f, -1.f));
    const Frame f(axis);
    auto at = [&](float deg) { return light.falloff(f.n * std::cos(deg * kPi / 180) + f.s * std::sin(deg * kPi / 180)); };
    EXPECT_FLOAT_EQ(at(0.f), 1.f);
    EXPECT_FLOAT_EQ(at(9.9f), 1.f);
    EXPECT_NEAR(at(15.f), 0.5f, 1e-4f);
    EXPECT_NEAR(at(17.5f), 0.25f, 1e-4f);
    EXPECT_EQ(at(20.1f), 0.f);
    // Seen from a point, it is a point light through the falloff.
    Color radiance;
    const Vec3 ref = Vec3(0.5f, 2.f, -1.f) + (f.n * std::cos(15 * kPi / 180) + f.s * std::sin(15 * kPi / 180)) * 2.f;
    const DirectionSample ds = light.sample_direction(ref, Vec2(0.3f, 0.3f), radiance);
    EXPECT_TRUE(ds.delta);
    EXPECT_NEAR(radiance.x, 3.f * 0.5f / 4.f, 1e-3f);
    EXPECT_THROW(tilted_spot(20.f, 20.f), std::invalid_argument);
}

namespace {

// A 4 x 4 bitmap whose texels are all distinct, so a wrong uv shows.
TexturePtr distinct_texels() {
    Image img(4, 4, 3);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            img.at(x, y, 0) = 0.1f + 0.2f * float(x);
            img.at(x, y, 1) = 0.1f + 0.2f * float(y);
            img.at(x, y, 2) = 0.05f + 0.06f * float(x + 4 * y);
        }
    BitmapOptions o;
    o.filter = FilterType::Nearest;
    o.raw = true;
    return std::make_shared<BitmapTexture>(img, o);
}

}  // namespace

// A spot light's projected texture (Mitsuba's uv = 0.5 + 0.5 (x, y) / (z tan cutoff) in its local frame)
// multiplies its intensity; its rays still fill the cone uniformly, and power() is their flux.
TEST(LightEmission, SpotLightProjectsItsTextureOverTheCone) {
    const Transform to_world = Transform::look_at(Vec3(0.5f, 2.f, -1.f), Vec3(0.2f, 0.f, 0.3f), Vec3(0, 1, 0));
    const TexturePtr tex = distinct_texels();
    const SpotLight light(to_world, Color(3.f, 2.f, 1.f), 30.f, 20.f, tex);
    expect_round_trip(light);
    const Chi2Result r = chi2_directions(light, Vec2(0.5f, 0.5f));
    ASSERT_TRUE(r.error.empty()) << r.describe();
    EXPECT_GT(r.p_value, 1e-4) << r.describe();
    EXPECT_NEAR(mean_flux(light), luminance(light.power()), 3e-3 * luminance(light.power()));
    // Inside the beam: local (x, y, 1) with x = t tan(cutoff) looks up u = 0.5 + 0.5 t; local +y is v.
    const float tan_c = std::tan(30.f * kPi / 180.f);
    for (auto [tx, ty] : {std::pair{0.2f, 0.1f}, std::pair{-0.3f, 0.25f}, std::pair{0.1f, -0.4f}}) {
        const Vec3 w = normalize(to_world.vector(Vec3(tx * tan_c, ty * tan_c, 1.f)));
        ASSERT_EQ(light.falloff(w), 1.f);
        SurfaceInteraction si;
        si.uv = Vec2(0.5f + 0.5f * tx, 0.5f + 0.5f * ty);
        const Color expect = Color(3.f, 2.f, 1.f) * tex->eval(si);
        const Color got = light.intensity(w);
        EXPECT_NEAR(got.x, expect.x, 1e-5f);
        EXPECT_NEAR(got.y, expect.y, 1e-5f);
        EXPECT_NEAR(got.z, expect.z, 1e-5f);
        Color radiance;
        light.sample_direction(Vec3(0.5f, 2.f, -1.f) + w * 2.f, Vec2(0.5f, 0.5f), radiance);
        EXPECT_NEAR(radiance.z, expect.z / 4.f, 1e-5f);
    }
    // Mitsuba refuses a texture that does not vary.
    EXPECT_THROW(SpotLight(to_world, Color(1.f), 30.f, 20.f, constant_texture(Color(0.5f))), std::invalid_argument);
}

// Mitsuba's directional light: every emitted ray travels along its direction, from a disk across the
// scene's bounding sphere, and the rays carry irradiance × the disk's area; seen from a point, a delta
// toward the light bringing the irradiance.
TEST(LightEmission, DirectionalLightEmitsParallelRaysAcrossTheScene) {
    DirectionalLight light(Vec3(0.5f, -1.f, -0.3f), Color(2.f, 1.8f, 1.5f));
    BBox b;
    b.expand(Vec3(-1, 0, -2));
    b.expand(Vec3(2, 3, 1));
    light.prepare(b);
    const Vec3 travel = normalize(Vec3(0.5f, -1.f, -0.3f));
    PCG32 rng(5, 9);
    double flux = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        const EmissionSample es = light.sample_emission(rng.next_2d(), rng.next_2d());
        ASSERT_TRUE(es.valid());
        ASSERT_NEAR(dot(es.ray.d, travel), 1.f, 1e-5f);
        const EmissionDensity d = light.pdf_emission(es.p, es.n, es.ns, es.ray.d);
        ASSERT_NEAR(d.pos, es.pdf_pos, 1e-6f * es.pdf_pos);
        flux += luminance(es.radiance) / (es.pdf_pos * es.pdf_dir);
    }
    EXPECT_NEAR(flux / n, luminance(light.power()), 1e-4 * luminance(light.power()));
    Color radiance;
    const DirectionSample ds = light.sample_direction(Vec3(0.3f, 1.f, 0.f), Vec2(0.1f, 0.9f), radiance);
    EXPECT_TRUE(ds.delta && light.is_delta() && light.is_infinite());
    EXPECT_NEAR(dot(ds.d, -travel), 1.f, 1e-6f);
    EXPECT_EQ(ds.dist, kInfinity);
    EXPECT_FLOAT_EQ(radiance.x, 2.f);
    EXPECT_EQ(light.eval_environment(-travel), Color(0.f));  // nothing can hit a delta
    EXPECT_THROW(DirectionalLight(Vec3(0.f), Color(1.f)), std::invalid_argument);
}

namespace {

ProjectorLight tilted_projector(float fov, const std::string &axis, int w, int h) {
    Camera frame;
    frame.to_world = Transform::look_at(Vec3(0.5f, 2.f, -1.f), Vec3(0.2f, 0.f, 0.3f), Vec3(0, 1, 0));
    frame.fov = fov;
    frame.fov_axis = axis;
    frame.width = w;
    frame.height = h;
    return ProjectorLight(frame, constant_texture(Color(0.8f, 0.6f, 0.4f)), 1.5f);
}

}  // namespace

// Mitsuba's projector: its rays cover the image plane uniformly (chi-square against pdf_emission, which
// is the perspective camera's 1 / (A cos^3)), carry pi scale E / cos^3, and add up to the power it
// reports (pi scale E A); seen from a point, a delta bringing pi scale E / (z^2 cos), Mitsuba's formula;
// nothing outside its frustum.
TEST(LightEmission, ProjectorLightEmitsItsImageThroughThePerspectiveMapping) {
    for (auto [fov, axis, w, h] : {std::tuple{40.f, "x", 1, 1}, std::tuple{70.f, "y", 6, 3}, std::tuple{120.f, "x", 2, 5}}) {
        const ProjectorLight light = tilted_projector(fov, axis, w, h);
        expect_round_trip(light);
        // The frustum's straight edges cut cells anywhere: their integrals need many points.
        const Chi2Result r = chi2_directions(light, Vec2(0.5f, 0.5f), 48);
        ASSERT_TRUE(r.error.empty()) << r.describe();
        EXPECT_GT(r.p_value, 1e-4) << r.describe();
        EXPECT_NEAR(mean_flux(light), luminance(light.power()), 2e-3 * luminance(light.power())) << fov;
    }
    const ProjectorLight light = tilted_projector(40.f, "x", 1, 1);
    const Vec3 origin(0.5f, 2.f, -1.f), axis = normalize(Vec3(0.2f, 0.f, 0.3f) - origin);
    const Frame f(axis);
    const float tan_x = std::tan(20.f * kPi / 180.f);
    Color radiance;
    for (float t : {0.f, 0.5f, 0.95f}) {  // along the image's x: cos theta = 1 / sqrt(1 + (t tan_x)^2)
        const Vec3 local_dir = normalize(f.n + f.s * (t * tan_x));
        const float cos_theta = dot(local_dir, axis), dist = 2.5f, z = dist * cos_theta;
        const DirectionSample ds = light.sample_direction(origin + local_dir * dist, Vec2(0.3f, 0.3f), radiance);
        EXPECT_TRUE(ds.delta);
        EXPECT_NEAR(radiance.x, kPi * 1.5f * 0.8f / (z * z * cos_theta), 1e-4f) << t;
    }
    light.sample_direction(origin + normalize(f.n + f.s * (1.05f * tan_x)) * 2.f, Vec2(0.3f, 0.3f), radiance);
    EXPECT_TRUE(is_black(radiance));  // just outside the image
    light.sample_direction(origin - axis * 2.f, Vec2(0.3f, 0.3f), radiance);
    EXPECT_TRUE(is_black(radiance));  // behind it
    EXPECT_THROW(tilted_projector(180.f, "x", 1, 1), std::invalid_argument);
}
