// The shading frame a hit gets: aligned with dp/du (Mitsuba's convention) where the shape's BSDF reads
// tangents (bump maps, anisotropic roughness), built from the normal alone where it does not. Either
// way it is orthonormal around the same interpolated normal, so isotropic BSDFs give the same values.
#include <gtest/gtest.h>

#include "neepp/shapes/triangle_mesh.h"
#include "neepp/shapes/sphere.h"
#include "neepp/materials/diffuse.h"
#include "neepp/materials/roughconductor.h"
#include "neepp/materials/bumpmap.h"
#include "neepp/materials/mask.h"
#include "neepp/materials/null.h"
#include "neepp/materials/twosided.h"
#include "neepp/sampling/rng.h"

using namespace neepp;

namespace {

// One bent quad with vertex normals and texture coordinates whose u axis is not along an edge.
TriangleMesh make_quad(BSDFPtr bsdf) {
    TriangleMesh s;
    s.positions = {{0, 0, 0}, {2, 0, 0.3f}, {2, 1.5f, 0.8f}, {0, 1, 0}};
    s.normals = {normalize(Vec3(0.1f, 0, 1)), normalize(Vec3(-0.2f, 0.1f, 1)), normalize(Vec3(0, -0.3f, 1)),
                 Vec3(0, 0, 1)};
    s.uvs = {{0, 0}, {0.7f, 0.7f}, {0, 1.4f}, {-0.5f, 0.5f}};
    s.indices = {0, 1, 2, 0, 2, 3};
    s.bsdf = std::move(bsdf);
    s.finalize();
    return s;
}

void expect_orthonormal(const Frame &f) {
    EXPECT_NEAR(norm(f.s), 1.f, 1e-5f);
    EXPECT_NEAR(norm(f.t), 1.f, 1e-5f);
    EXPECT_NEAR(norm(f.n), 1.f, 1e-5f);
    EXPECT_NEAR(dot(f.s, f.t), 0.f, 1e-5f);
    EXPECT_NEAR(dot(f.s, f.n), 0.f, 1e-5f);
    EXPECT_NEAR(norm(cross(f.s, f.t) - f.n), 0.f, 1e-5f);  // right-handed
}

TEST(ShadingFrame, WhichBsdfsNeedTangents) {
    auto diffuse = std::make_shared<DiffuseBSDF>(constant_texture(Color(0.5f)));
    auto bump = std::make_shared<BumpMapBSDF>(constant_texture(0.f), 1.f, diffuse);
    TexturePtr a = constant_texture(0.2f), b = constant_texture(0.05f);
    auto isotropic = std::make_shared<RoughConductorBSDF>(MicrofacetType::GGX, a, a, constant_texture(Color(0.2f)),
                                                          constant_texture(Color(3.f)));
    auto anisotropic = std::make_shared<RoughConductorBSDF>(MicrofacetType::GGX, a, b, constant_texture(Color(0.2f)),
                                                            constant_texture(Color(3.f)));
    EXPECT_FALSE(diffuse->needs_tangents());
    EXPECT_TRUE(bump->needs_tangents());
    EXPECT_FALSE(isotropic->needs_tangents());
    EXPECT_TRUE(anisotropic->needs_tangents());
    EXPECT_FALSE(TwoSidedBSDF(diffuse, nullptr).needs_tangents());
    EXPECT_TRUE(TwoSidedBSDF(diffuse, bump).needs_tangents());
    EXPECT_TRUE(MaskBSDF(constant_texture(0.5f), anisotropic).needs_tangents());
    EXPECT_FALSE(make_quad(diffuse).tangents);
    EXPECT_EQ(make_quad(diffuse).bsdf_flags, uint32_t(BSDFDiffuseReflection));  // what the integrator reads
    EXPECT_EQ(make_quad(std::make_shared<MaskBSDF>(constant_texture(0.5f), anisotropic)).bsdf_flags,
              uint32_t(BSDFGlossyReflection | BSDFNull));
    EXPECT_TRUE(make_quad(std::make_shared<TwoSidedBSDF>(bump, nullptr)).tangents);
}

// A BSDF that does not say whether it reads the tangent (a new plugin's) gets the full frame: the default
// is right for every BSDF, the cheaper frame is an opt-in.
TEST(ShadingFrame, ABsdfThatDoesNotSayGetsTangents) {
    struct Plain final : BSDF {
        Color eval(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const override { return Color(0.f); }
        float pdf(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, const Vec3 &) const override { return 0.f; }
        BSDFSample sample(const BSDFContext &, const SurfaceInteraction &, const Vec3 &, float, Vec2) const override { return {}; }
        uint32_t flags() const override { return BSDFGlossyReflection; }
    };
    EXPECT_TRUE(make_quad(std::make_shared<Plain>()).tangents);
}

TEST(ShadingFrame, SameNormalAndUvWithOrWithoutTangents) {
    auto diffuse = std::make_shared<DiffuseBSDF>(constant_texture(Color(0.5f)));
    const TriangleMesh plain = make_quad(diffuse);
    const TriangleMesh bumped = make_quad(std::make_shared<BumpMapBSDF>(constant_texture(0.f), 1.f, diffuse));
    ASSERT_FALSE(plain.tangents);
    ASSERT_TRUE(bumped.tangents);
    PCG32 rng(11, 3);
    for (int k = 0; k < 200; ++k) {
        const uint32_t prim = k % 2;
        float b1 = rng.next_float(), b2 = rng.next_float();
        if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
        const Ray ray{Vec3(1, 0.5f, 3), Vec3(0, 0, -1), 0.f, kInfinity};
        SurfaceInteraction a, b;
        plain.fill_interaction(prim, b1, b2, ray, 2.f, a);
        bumped.fill_interaction(prim, b1, b2, ray, 2.f, b);
        expect_orthonormal(a.sh_frame);
        expect_orthonormal(b.sh_frame);
        EXPECT_NEAR(norm(a.sh_frame.n - b.sh_frame.n), 0.f, 1e-6f);
        EXPECT_NEAR(norm(a.n - b.n), 0.f, 1e-6f);
        EXPECT_NEAR(norm(a.p - b.p), 0.f, 1e-6f);
        EXPECT_NEAR(a.uv.x, b.uv.x, 1e-6f);
        EXPECT_NEAR(a.uv.y, b.uv.y, 1e-6f);
        // With tangents: s is dp/du with its normal component removed.
        const Vec3 s = b.dpdu - b.sh_frame.n * dot(b.sh_frame.n, b.dpdu);
        EXPECT_NEAR(norm(b.sh_frame.s - normalize(s)), 0.f, 1e-5f);
    }
}

}  // namespace

namespace {

// A sphere's frame follows dp/du (the azimuth direction) where its BSDF reads tangents, as Mitsuba's does.
TEST(ShadingFrame, SphereFrameFollowsDpDuWhenTangentsAreRead) {
    TexturePtr a = constant_texture(0.2f), b = constant_texture(0.05f);
    Sphere s;
    s.center = Vec3(0.5f, -0.2f, 1.f);
    s.radius = 2.f;
    s.bsdf = std::make_shared<RoughConductorBSDF>(MicrofacetType::GGX, a, b, constant_texture(Color(0.2f)),
                                                  constant_texture(Color(3.f)));
    s.finalize();
    ASSERT_TRUE(s.tangents);
    PCG32 rng(5, 7);
    for (int k = 0; k < 100; ++k) {
        const Vec2 u = rng.next_2d();
        const float z = 1.f - 2.f * u.y, r = std::sqrt(std::max(0.f, 1.f - z * z)), phi = 2.f * kPi * u.x;
        const Vec3 dir(r * std::cos(phi), r * std::sin(phi), z);
        const Ray ray{s.center + dir * 5.f, -dir, 0.f, kInfinity};
        SurfaceInteraction si;
        s.fill_interaction(0, 0.f, 0.f, ray, 3.f, si);
        expect_orthonormal(si.sh_frame);
        EXPECT_NEAR(norm(si.sh_frame.n - dir), 0.f, 1e-5f);
        EXPECT_NEAR(norm(si.sh_frame.s - normalize(Vec3(-dir.y, dir.x, 0.f))), 0.f, 1e-4f);
    }
}

// A turned sphere's uv and dp/du follow its own axes: at the world point along its local direction
// (sin θ cos φ, sin θ sin φ, cos θ), uv is (φ / 2π, θ / π) whatever the turn, as in Mitsuba.
TEST(ShadingFrame, TurnedSphereUvFollowsItsAxes) {
    Sphere s;
    s.center = Vec3(1.f, 2.f, 3.f);
    s.radius = 0.5f;
    // Local x, y, z along world y, z, x: a proper rotation.
    s.axes[0] = Vec3(0, 1, 0), s.axes[1] = Vec3(0, 0, 1), s.axes[2] = Vec3(1, 0, 0);
    s.bsdf = std::make_shared<RoughConductorBSDF>(MicrofacetType::GGX, constant_texture(0.2f), constant_texture(0.2f),
                                                  constant_texture(Color(0.2f)), constant_texture(Color(3.f)));
    s.finalize();
    for (const auto &[theta, phi] : std::vector<std::pair<float, float>>{{0.7f, 0.3f}, {2.1f, 4.0f}, {1.2f, 5.9f}}) {
        const Vec3 local(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        const Vec3 dir = s.axes[0] * local.x + s.axes[1] * local.y + s.axes[2] * local.z;
        const Ray ray{s.center + dir * 3.f, -dir, 0.f, kInfinity};
        SurfaceInteraction si;
        s.fill_interaction(0, 0.f, 0.f, ray, 2.5f, si);
        EXPECT_NEAR(si.uv.x, phi / (2 * kPi), 1e-5f);
        EXPECT_NEAR(si.uv.y, theta / kPi, 1e-5f);
        const Vec3 dpdu_local(-local.y, local.x, 0.f);
        const Vec3 dpdu = (s.axes[0] * dpdu_local.x + s.axes[1] * dpdu_local.y) * (2 * kPi * s.radius);
        EXPECT_LT(norm(si.dpdu - dpdu), 1e-4f);
        EXPECT_NEAR(norm(si.sh_frame.s - normalize(dpdu)), 0.f, 1e-4f);
    }
}

}  // namespace
