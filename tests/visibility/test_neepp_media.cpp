// NEE++ through participating media: the map learns expected transmittance (the seeding's samples and
// rendering's shadow rays are ratio-tracking estimates in [0, 1], not hits), and every policy and the
// visibility-aware light choice render the image of volumetric NEE, with the map right or badly wrong.
// The scene: the two rooms of the door tests filled with a heterogeneous fog, the camera in it.
#include <gtest/gtest.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include "common/volume_grid_writer.h"
#include "neepp/integrators/path.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/map_seeding.h"
#include "neepp/visibility/neepp_shadow_rays.h"
#include "test_scenes.h"
#include "visibility_test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// The two rooms (a wall with a door between them, the lamp under the far room's ceiling) inside a fog
// whose density varies over the rooms (a 4 x 4 x 4 grid, trilinear), so that transmittance estimates are
// fractional; with the door closed for a wrong map.
std::string fog_rooms_xml(bool door_closed) {
    std::string xml = R"(<scene version="3.0.0">
  <integrator type="volpath"><integer name="max_depth" value="5"/></integrator>
  <medium type="heterogeneous" id="fog">
    <volume name="sigma_t" type="gridvolume"><string name="filename" value="fog.vol"/>
      <transform name="to_world"><scale x="4" y="2" z="2"/><translate x="-2" z="-1"/></transform></volume>
    <float name="scale" value="0.8"/><float name="albedo" value="0.8"/>
    <phase type="hg"><float name="g" value="0.3"/></phase>
  </medium>
  <sensor type="perspective"><float name="fov" value="75"/>
    <transform name="to_world"><lookat origin="-1.9,1.2,0.7" target="0,0.7,-0.1" up="0,1,0"/></transform>
    <ref id="fog"/>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>)";
    return xml + two_rooms_shapes_xml(door_closed, R"(<ref id="fog" name="interior"/>)") + "</scene>\n";
}

// The fog's density: thin near the floor, denser toward the ceiling and the far room.
void write_fog_grid(const std::string &scene_path) {
    VolumeGridFile g;
    g.size[0] = g.size[1] = g.size[2] = 4;
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 4; ++x) g.values.push_back(0.2f + 0.25f * float(y) + 0.15f * float(x) + 0.05f * float((x + z) % 2));
    std::ofstream(std::filesystem::path(scene_path).parent_path() / "fog.vol", std::ios::binary) << volume_grid_bytes(g);
}

const std::string &fog_rooms(bool door_closed = false) {
    static std::map<bool, std::string> paths;
    auto it = paths.find(door_closed);
    if (it == paths.end()) {
        const std::string p = write_temp_scene(fog_rooms_xml(door_closed));
        write_fog_grid(p);
        it = paths.emplace(door_closed, p).first;
    }
    return it->second;
}

enum class MapSetup { Built, ClaimsOccluded, FromClosedDoor };

struct Moments : BlockMoments {
    uint64_t shadow_rays = 0, skipped = 0;
};

Moments render_moments(const OptionMap &options, uint64_t seed0, MapSetup setup = MapSetup::Built) {
    constexpr int kSeeds = 6, kSpp = 48;
    std::vector<std::vector<double>> per_seed;
    Moments m;
    for (int s = 0; s < kSeeds; ++s) {
        auto scene = load_scene(fog_rooms());
        auto integ = make_integrator("volpath", with_scene_options(*scene, Options(options)));
        if (setup != MapSetup::Built) {
            auto *tester = dynamic_cast<NeeppShadowRays *>(&dynamic_cast<PathIntegrator &>(*integ).shadow_rays());
            EXPECT_NE(tester, nullptr);
            if (!tester) return m;
            if (setup == MapSetup::ClaimsOccluded) plant_map_claiming_everything_occluded(*tester, *scene);
            else plant_map_seeded_on(*tester, *load_scene(fog_rooms(true)));
        }
        RenderJob job;
        job.spp = kSpp;
        job.seed = seed0 + uint64_t(s) * 7919;
        const RenderResult r = render(*scene, *integ, job);
        m.shadow_rays += r.counters.shadow_rays;
        m.skipped += r.counters.shadow_rays_skipped;
        per_seed.push_back(block_means(r.image, 6, 6));
    }
    static_cast<BlockMoments &>(m) = moments_over_seeds(per_seed);
    return m;
}

const Moments &volumetric_nee() {
    static const Moments m = render_moments({}, 101);
    return m;
}

class FogPolicy : public ::testing::TestWithParam<std::string> {};

TEST_P(FogPolicy, AgreesWithVolumetricNee) {
    const Moments pol = render_moments({{"shadow_rays", GetParam()}}, 5003);
    expect_same_image(volumetric_nee(), pol, GetParam() + " through fog");
    EXPECT_GT(pol.skipped, 0u) << "the policy never skipped a ray: the test would not exercise the roulette";
    EXPECT_LT(pol.shadow_rays, volumetric_nee().shadow_rays);
}

TEST_P(FogPolicy, StaysUnbiasedWhenTheMapClaimsEverythingOccluded) {
    const Moments pol = render_moments({{"shadow_rays", GetParam()}, {"learn", "false"}}, 7001, MapSetup::ClaimsOccluded);
    expect_same_image(volumetric_nee(), pol, GetParam() + " through fog, map claims occluded");
    EXPECT_GT(pol.skipped, 0u);
}

TEST_P(FogPolicy, StaysUnbiasedWithAMapSeededBehindAClosedDoor) {
    const Moments pol = render_moments({{"shadow_rays", GetParam()}, {"learn", "false"}}, 9001, MapSetup::FromClosedDoor);
    expect_same_image(volumetric_nee(), pol, GetParam() + " through fog, map from the closed door");
    EXPECT_GT(pol.skipped, 0u);
}

INSTANTIATE_TEST_SUITE_P(Neepp, FogPolicy, ::testing::Values("neepp", "neepp-adaptive", "neepp-cv"), policy_test_name);

TEST(NeeppThroughFog, VisibilityAwareLightChoiceAndAutoAgreeWithVolumetricNee) {
    expect_same_image(volumetric_nee(), render_moments({{"light_sampler", "visibility"}}, 11003), "light_sampler=visibility");
    expect_same_image(volumetric_nee(), render_moments({{"neepp", "auto"}}, 13001), "neepp=auto");
}

// In a fog with nothing in it but the lamp, the pre-pass records points where paths scatter (no surface
// holds them), and each pair's seeded fraction is its transmittance: over all pairs, the counts' ratio
// matches exp(-sigma_t d) between the cells' centres; without the fog every ray gets through.
TEST(NeeppThroughFog, SeedingLearnsTransmittanceBetweenPointsInAMedium) {
    constexpr float kSigmaT = 0.6f;
    auto xml = [&](bool fog) {
        const std::string medium = fog ? R"(<medium type="homogeneous" id="fog"><float name="sigma_t" value="0.6"/><float name="albedo" value="0.9"/></medium>)" : "";
        const std::string in_fog = fog ? R"(<ref id="fog"/>)" : "";
        const std::string interior = fog ? R"(<ref id="fog" name="interior"/>)" : "";
        return R"(<scene version="3.0.0"><integrator type="volpath"/>)" + medium + R"(
  <sensor type="perspective"><float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,0,2.5" target="0,0,0" up="0,1,0"/></transform>)" + in_fog + R"(
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
  <shape type="cube"><transform name="to_world"><scale value="3"/></transform><bsdf type="null"/>)" + interior + R"(</shape>
  <shape type="sphere"><float name="radius" value="0.05"/><point name="center" x="1" y="1" z="-1"/>
    <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
</scene>)";
    };
    for (bool fog : {true, false}) {
        auto scene = load_scene(write_temp_scene(xml(fog)));
        VoxelGrid grid(scene->bounds(), 8);
        VisibilityMap map(grid.cell_count());
        SeedingOptions opt;
        opt.camera_grid = 32;
        const SeedingStats stats = seed_visibility_map(*scene, grid, map, opt);
        if (!fog) {
            // Paths leave through the null box at once: only its faces and the lamp are met.
            for (uint64_t p = 0; p < map.pair_count(); ++p) EXPECT_EQ(map.counts_at(p).visible, map.counts_at(p).traced);
            continue;
        }
        EXPECT_GT(stats.occupied_voxels, 40u) << "points where paths scatter in the fog fill the voxels";
        const Vec3 cell = (grid.bounds().hi - grid.bounds().lo) / float(grid.resolution());
        auto centre = [&](uint32_t c) {
            int x, y, z;
            grid.voxel_coords(c, x, y, z);
            return grid.bounds().lo + Vec3(float(x) + 0.5f, float(y) + 0.5f, float(z) + 0.5f) * cell;
        };
        double visible = 0, traced = 0, expected = 0;
        const uint32_t lamp = grid.voxel_of(Vec3(1.f, 1.f, -1.f));
        for (uint32_t a = 0; a < grid.voxel_count(); ++a) {
            if (a == lamp) continue;
            const PairCounts c = map.counts(a, lamp);
            if (!c.traced) continue;
            visible += c.visible;
            traced += c.traced;
            expected += c.traced * std::exp(-kSigmaT * norm(centre(a) - Vec3(1.f, 1.f, -1.f)));
        }
        ASSERT_GT(traced, 1000) << "pairs with the lamp's voxel were seeded";
        EXPECT_NEAR(visible / traced, expected / traced, 0.04) << "seeded fraction vs exp(-sigma_t d)";
        EXPECT_LT(visible / traced, 0.8);
    }
}

}  // namespace
