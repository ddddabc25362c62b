// Triangle hits filled 8 at a time (HitLanes) give the hit records the scalar fill gives
// (Scene::fill: fill_interaction, then wi), for every kind of mesh a lane can hold: vertex normals or
// not, face normals forced, flipped normals, texture coordinates or not, a vertex normal that cancels
// out, and any number of lanes in use.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "neepp/materials/diffuse.h"
#include "neepp/sampling/rng.h"
#include "neepp/shapes/hit_lanes.h"

using namespace neepp;

namespace {

std::unique_ptr<TriangleMesh> make_mesh(bool normals, bool uvs, bool flip, bool face_normals, bool cancelling_normal) {
    auto s = std::make_unique<TriangleMesh>();
    s->positions = {{0, 0, 0}, {2, 0, 0.3f}, {2, 1.5f, 0.8f}, {0, 1, 0}};
    if (normals) {
        s->normals = {normalize(Vec3(0.1f, 0, 1)), normalize(Vec3(-0.2f, 0.1f, 1)), normalize(Vec3(0, -0.3f, 1)),
                      Vec3(0, 0, 1)};
        // Opposite normals at two corners: their midpoint interpolates to zero, where the face normal is used.
        if (cancelling_normal) s->normals[2] = -s->normals[0];
    }
    if (uvs) s->uvs = {{0, 0}, {0.7f, 0.7f}, {0, 1.4f}, {-0.5f, 0.5f}};
    s->indices = {0, 1, 2, 0, 2, 3};
    s->flip_normals = flip;
    s->face_normals = face_normals;
    s->bsdf = std::make_shared<DiffuseBSDF>(constant_texture(Color(0.5f)));
    s->finalize();
    return s;
}

void expect_near(const Vec3 &a, const Vec3 &b, const char *what) {
    EXPECT_NEAR(a.x, b.x, 2e-6f) << what;
    EXPECT_NEAR(a.y, b.y, 2e-6f) << what;
    EXPECT_NEAR(a.z, b.z, 2e-6f) << what;
}

struct Hit {
    const TriangleMesh *shape;
    uint32_t prim;
    float b1, b2, t;
    Vec3 d;
};

void expect_same_record(const SurfaceInteraction &wide, const Hit &h) {
    SurfaceInteraction ref;
    h.shape->fill_interaction(h.prim, h.b1, h.b2, Ray{Vec3(), h.d}, h.t, ref);
    ref.wi = ref.to_local(-h.d);
    EXPECT_EQ(wide.shape, ref.shape);
    EXPECT_EQ(wide.prim_index, ref.prim_index);
    EXPECT_EQ(wide.t, ref.t);
    expect_near(wide.p, ref.p, "p");
    expect_near(wide.n, ref.n, "n");
    expect_near(wide.sh_frame.s, ref.sh_frame.s, "s");
    expect_near(wide.sh_frame.t, ref.sh_frame.t, "t");
    expect_near(wide.sh_frame.n, ref.sh_frame.n, "shading normal");
    EXPECT_NEAR(wide.uv.x, ref.uv.x, 2e-6f);
    EXPECT_NEAR(wide.uv.y, ref.uv.y, 2e-6f);
    EXPECT_EQ(wide.dpdu, Vec3(0.f));
    EXPECT_EQ(wide.dpdv, Vec3(0.f));
    expect_near(wide.wi, ref.wi, "wi");
}

TEST(FillLanes, SameRecordsAsOneAtATime) {
    std::vector<std::unique_ptr<TriangleMesh>> shapes;
    for (int bits = 0; bits < 32; ++bits)
        shapes.push_back(make_mesh(bits & 1, bits & 2, bits & 4, bits & 8, bits & 16));
    for (const auto &s : shapes) ASSERT_TRUE(s->fills_in_lanes());
    PCG32 rng(5, 9);
    for (int round = 0; round < 400; ++round) {
        const int n = 1 + round % HitLanes::kLanes;  // every lane count
        Hit hits[HitLanes::kLanes];
        SurfaceInteraction out[HitLanes::kLanes];
        HitLanes lanes;
        for (int i = 0; i < n; ++i) {
            Hit &h = hits[i];
            h.shape = shapes[rng.next_u32() % shapes.size()].get();
            h.prim = rng.next_u32() % 2;
            h.b1 = rng.next_float(), h.b2 = rng.next_float();
            if (h.b1 + h.b2 > 1) h.b1 = 1 - h.b1, h.b2 = 1 - h.b2;
            // A cancelling normal is hit where it cancels: the midpoint of corners 0 and 2 (prim 0's b2 = 0.5).
            if (round % 7 == 0) h.prim = 0, h.b1 = 0, h.b2 = 0.5f;
            h.t = 0.5f + rng.next_float();
            h.d = normalize(Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, -1.f));
            add_lane(lanes, *h.shape, h.prim, h.b1, h.b2, h.t, h.d, out[i]);
        }
        fill_lanes(lanes);  // (the eighth lane has filled them already)
        EXPECT_EQ(lanes.n, 0);
        for (int i = 0; i < n; ++i) expect_same_record(out[i], hits[i]);
    }
}

TEST(FillLanes, ShapesThatNeedTangentsFillOneAtATime) {
    auto s = make_mesh(true, true, false, false, false);
    s->tangents = true;  // as finalize() sets for a bump-mapped or anisotropic BSDF
    EXPECT_FALSE(s->fills_in_lanes());
}

}  // namespace
