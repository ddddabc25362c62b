// LightBounds: cone unions hold both cones, and the importance bound is conservative: wherever it is
// zero, no point of the light can send light to the receiver (else the BVH sampler would be biased).
#include <gtest/gtest.h>
#include "neepp/shapes/triangle_mesh.h"
#include "neepp/base/light_bounds.h"
#include "neepp/base/texture.h"
#include "neepp/lights/area_light.h"
#include "neepp/math/warp.h"
#include "neepp/sampling/rng.h"

namespace neepp {
namespace {

DirectionCone random_cone(PCG32 &rng) {
    return {square_to_uniform_sphere(rng.next_2d()), 2.f * rng.next_float() - 1.f};
}

// A direction inside the cone, uniformly over its spherical cap.
Vec3 direction_in(const DirectionCone &c, PCG32 &rng) {
    Vec2 u = rng.next_2d();
    float cos_t = 1.f - u.x * (1.f - c.cos_theta);
    float sin_t = std::sqrt(std::max(0.f, 1.f - cos_t * cos_t));
    float phi = 2 * kPi * u.y;
    Frame f(c.w);
    return f.to_world(Vec3(std::cos(phi) * sin_t, std::sin(phi) * sin_t, cos_t));
}

TEST(LightBounds, ConeUnionHoldsBothCones) {
    PCG32 rng(3, 4);
    for (int t = 0; t < 2000; ++t) {
        DirectionCone a = random_cone(rng), b = random_cone(rng);
        if (t % 3 == 0) a.cos_theta = 1.f;  // single directions too
        DirectionCone u = cone_union(a, b);
        for (int k = 0; k < 20; ++k) {
            for (const DirectionCone *c : {&a, &b}) {
                Vec3 d = direction_in(*c, rng);
                ASSERT_GE(dot(u.w, d), u.cos_theta - 2e-4f) << "trial " << t;
            }
        }
    }
}

TEST(LightBounds, ImportanceIsZeroOnlyWhereTheLightCannotReach) {
    // Random one-sided rectangles (as area lights) and random receivers; wherever the importance of the
    // light's bounds is zero, every sampled light point must send zero radiance toward the receiver.
    PCG32 rng(11, 2);
    int zero = 0, positive = 0;
    for (int t = 0; t < 400; ++t) {
        TriangleMesh rect;
        Vec3 c(4 * rng.next_float() - 2, 4 * rng.next_float() - 2, 4 * rng.next_float() - 2);
        Vec3 n = square_to_uniform_sphere(rng.next_2d());
        Frame f(n);
        float sx = 0.05f + rng.next_float(), sy = 0.05f + rng.next_float();
        rect.positions = {c - f.s * sx - f.t * sy, c + f.s * sx - f.t * sy, c + f.s * sx + f.t * sy, c - f.s * sx + f.t * sy};
        rect.indices = {0, 1, 2, 0, 2, 3};
        rect.finalize();
        AreaLight light(&rect, std::make_shared<ConstantTexture>(Color(1.f)));
        LightBounds b = *light.bounds();
        EXPECT_GT(dot(b.normals.w, n), 0.999f);
        for (int k = 0; k < 50; ++k) {
            Vec3 p(6 * rng.next_float() - 3, 6 * rng.next_float() - 3, 6 * rng.next_float() - 3);
            Vec3 pn = k % 2 ? square_to_uniform_sphere(rng.next_2d()) : Vec3(0.f);
            if (b.importance(p, pn) > 0) {
                ++positive;
                continue;
            }
            ++zero;
            for (int s = 0; s < 64; ++s) {
                Color Le;
                DirectionSample ds = light.sample_direction(p, rng.next_2d(), Le);
                ASSERT_TRUE(is_black(Le) || !(ds.pdf > 0)) << "importance 0 but the light reaches p (trial " << t << ")";
            }
        }
    }
    EXPECT_GT(zero, 1000);  // both cases are exercised
    EXPECT_GT(positive, 1000);
}

}  // namespace
}  // namespace neepp
