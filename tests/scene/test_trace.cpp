// Scene queries: a packet of rays (trace16, occluded16; full or partial, at every packet width) finds the
// same hits as one ray at a time, and trace + fill gives the hit record intersect gives.
#include <gtest/gtest.h>
#include "neepp/sampling/rng.h"
#include "neepp/math/warp.h"
#include "neepp/scene/scene.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

std::unique_ptr<Scene> boxes_scene() {
    return load_scene(write_temp_scene(scene_header_xml(4, 60, "0,1,3", "0,0.5,0", 8, 8) + R"(
  <bsdf type="diffuse" id="white"/>
  <shape type="cube"><transform name="to_world"><scale value="0.5"/></transform><ref id="white"/></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="1" y="0.6"/></transform><ref id="white"/></shape>
  <shape type="sphere"><point name="center" x="-1" y="0.4" z="0"/><float name="radius" value="0.4"/><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/><translate y="-0.5"/></transform><ref id="white"/></shape>
  <emitter type="constant"/>
</scene>)"));
}

TEST(SceneTrace, PacketsFindTheSameHitsAsSingleRays) {
    auto scene = boxes_scene();
    PCG32 rng;
    rng.seed(3, 5);
    int hits = 0;
    EXPECT_TRUE(scene->packet_width() == 4 || scene->packet_width() == 8 || scene->packet_width() == 16);
    EXPECT_THROW(scene->set_packet_width(12), std::invalid_argument);
    for (int width : {16, 8, 4})
    for (int n : {16, 9, 7, 1}) {
        scene->set_packet_width(width);
        for (int round = 0; round < 200; ++round) {
            std::vector<Ray> rays(n);
            std::vector<RayHit> packet(n);
            std::vector<const Ray *> rp(n);
            std::vector<RayHit *> hp(n);
            for (int i = 0; i < n; ++i) {
                Vec3 o(rng.next_float() * 4 - 2, rng.next_float() * 2, rng.next_float() * 4 - 2);
                rays[i] = Ray{o, square_to_uniform_sphere(rng.next_2d()), 0.f, i % 3 == 0 ? 1.5f : kInfinity};
                rp[i] = &rays[i], hp[i] = &packet[i];
            }
            scene->trace16(rp.data(), hp.data(), n);
            for (bool coherent : {false, true}) {
                bool occluded[16];
                scene->occluded16(rp.data(), n, occluded, coherent);
                for (int i = 0; i < n; ++i) ASSERT_EQ(occluded[i], scene->occluded(rays[i]))
                        << "ray " << i << " of " << n << ", width " << width << (coherent ? ", coherent" : "");
            }
            for (int i = 0; i < n; ++i) {
                const RayHit single = scene->trace(rays[i]);
                ASSERT_EQ(single.valid(), packet[i].valid()) << "ray " << i << " of " << n << ", width " << width;
                if (!single.valid()) continue;
                ++hits;
                EXPECT_EQ(single.geom, packet[i].geom);
                EXPECT_EQ(single.prim, packet[i].prim);
                EXPECT_NEAR(single.t, packet[i].t, 1e-5f * (1 + single.t));
                EXPECT_LE(packet[i].t, rays[i].tmax);
                SurfaceInteraction a, b;
                ASSERT_TRUE(scene->intersect(rays[i], a));
                scene->fill(packet[i], rays[i], b);
                EXPECT_NEAR(norm(a.p - b.p), 0.f, 1e-4f);
                EXPECT_EQ(a.shape, b.shape);
            }
        }
    }
    EXPECT_GT(hits, 4000);  // a quarter of the rays hit something
}

}  // namespace
