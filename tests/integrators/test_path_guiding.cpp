// Path guiding in the path integrator (guiding=sdtree, map and sdtree+map): the guided image against plain NEE's
// (per-block z-tests), with the guide learning as it renders and with guides that are deliberately wrong
// for the scene, which must cost variance only; images the same to the bit for a seed and thread count;
// the option accepted where it is implemented and refused elsewhere.
#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include "common/chi2.h"
#include "neepp/integrators/path.h"
#include "neepp/integrators/path_guiding.h"
#include "neepp/integrators/path_state.h"
#include "neepp/io/image.h"
#include "neepp/sampling/rng.h"
#include "neepp/scene/scene.h"
#include "test_scenes.h"

using namespace neepp;
using namespace neepp::testing;

namespace {

// A room open at the front onto a constant sky, lit also by an area light behind an occluder, with
// diffuse, glossy and specular surfaces: light arrives mostly indirectly, which is what a guide learns.
std::string lit_room_xml() {
    return scene_header_xml(8, 60, "0,1,3.5", "0,0.8,0", 24, 18) + R"(
  <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><translate z="-2"/></transform>
    <bsdf type="roughplastic"><float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.5,0.6,0.4"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="90"/><translate y="2"/></transform><ref id="white"/></shape>
  <shape type="sphere"><point name="center" x="0.6" y="0.5" z="0.3"/><float name="radius" value="0.4"/><bsdf type="dielectric"/></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.4"/><translate x="-0.5" y="0.4" z="-0.3"/></transform>
    <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.2"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="90"/><translate y="1.9" z="-1.5"/></transform>
    <emitter type="area"><rgb name="radiance" value="20"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.6"/><rotate x="1" angle="90"/><translate y="1.6" z="-1.4"/></transform><ref id="white"/></shape>
  <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
</scene>)";
}

const OptionMap kGuided = {{"guiding", "sdtree"}};

TEST(PathGuiding, OptionIsPathsAndRefusedElsewhere) {
    auto guided = make_integrator("path", Options(kGuided));
    EXPECT_EQ(guided->describe()["guiding"], "sdtree");
    EXPECT_EQ(guided->describe()["form"], "fast") << "both forms guide; the fast one by default";
    EXPECT_NE(dynamic_cast<RayIntegrator &>(*guided).batch(), nullptr);
    OptionMap reference = kGuided;
    reference["form"] = "reference";
    EXPECT_EQ(dynamic_cast<RayIntegrator &>(*make_integrator("path", Options(reference))).batch(), nullptr);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"guiding", "sdtree"}, {"guiding_bsdf_fraction", "0"}})),
                 std::invalid_argument) << "a guide alone could miss directions the BSDF reaches";
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"guiding", "sdtree"}, {"guiding_spatial_threshold", "-1"}})),
                 std::invalid_argument);
    EXPECT_EQ(make_integrator("path", Options())->describe()["guiding"], "none");
    EXPECT_NE(dynamic_cast<RayIntegrator &>(*make_integrator("path", Options(OptionMap{{"guiding", "none"}}))).batch(), nullptr);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"guiding", "ppg"}})), std::invalid_argument);
    for (const char *other : {"volpath", "bdpt", "light", "pssmlt"})
        EXPECT_THROW(make_integrator(other, Options(kGuided)), std::invalid_argument) << other;
    EXPECT_THROW(make_integrator("pssmlt", Options(OptionMap{{"guiding", "sdtree"}, {"bidirectional", "false"}})),
                 std::invalid_argument);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"guiding", "sdtree"}, {"neepp", "auto"}})), std::invalid_argument);
}

TEST(PathGuiding, GuideLearnsFromThePasses) {
    auto scene = load_scene(write_temp_scene(lit_room_xml()));
    auto integrator = make_integrator("path", with_scene_options(*scene, Options(kGuided)));
    RenderJob job;
    job.spp = 16;
    job.seed = 3;
    render(*scene, *integrator, job);
    const SDTree *guide = dynamic_cast<const PathIntegrator &>(*integrator).guide();
    ASSERT_NE(guide, nullptr);
    EXPECT_TRUE(guide->can_guide(guide->leaf_at(Vec3(0.f, 0.5f, 0.f))));
    EXPECT_GT(guide->records(), 1000u);
    EXPECT_GT(guide->sampling(0).leaf_count(), 4u) << "refined by what it recorded";
    EXPECT_TRUE(integrator->statistics().contains("guiding"));
}

// Block moments of the guided integrator; `guide` (when given) is installed before each render and kept.
BlockMoments guided_moments(const std::string &path, const OptionMap &o, int seeds, int spp, uint64_t seed0,
                            const SDTree *guide, const std::string *map_guide = nullptr) {
    std::vector<std::vector<double>> per_seed;
    for (int s = 0; s < seeds; ++s) {
        auto scene = load_scene(path);
        auto integrator = make_integrator("path", with_scene_options(*scene, Options(o)));
        auto &pi = dynamic_cast<PathIntegrator &>(*integrator);
        if (guide) pi.install_guide(std::make_unique<SDTree>(*guide));
        if (map_guide) {  // saved totals, on the grid this integrator's map will have
            pi.prepare(*scene);
            auto m = std::make_unique<MapGuide>(*pi.shadow_rays().voxel_grid());
            m->load(*map_guide);
            m->update(nullptr);
            pi.install_map_guide(std::move(m));
        }
        RenderJob job;
        job.spp = spp;
        job.seed = seed0 + 31 * s;
        per_seed.push_back(block_means(render(*scene, *integrator, job).image, 6, 6));
    }
    return moments_over_seeds(per_seed);
}

TEST(PathGuiding, UnbiasedAgainstPlainNee) {
    const std::vector<std::pair<std::string, std::string>> scenes = {{"lit room", lit_room_xml()},
                                                                      {"glossy room", kGlossyRoomXml}};
    for (const auto &[name, xml] : scenes) {
        const std::string path = write_temp_scene(xml);
        const BlockMoments nee = block_moments(path, "path", Options(), 6, 64, 101);
        expect_same_image(nee, guided_moments(path, kGuided, 6, 64, 202, nullptr), name + " guided");
        // Mostly the learned guide (a tenth of the directions by the BSDF).
        OptionMap mostly_guide = kGuided;
        mostly_guide["guiding_bsdf_fraction"] = "0.1";
        expect_same_image(nee, guided_moments(path, mostly_guide, 6, 64, 252, nullptr), name + " guided, bsdf_fraction 0.1");
        OptionMap bsdf_only = kGuided;
        bsdf_only["nee"] = "false";
        expect_same_image(nee, guided_moments(path, bsdf_only, 6, 64, 303, nullptr), name + " guided, nee=false");
    }
}

// A tree that sends nearly every guided direction into a narrow cone around `lobe`, wherever the point.
SDTree cone_guide(const BBox &bounds, const Vec3 &lobe) {
    SDTree t(bounds);
    PCG32 rng(5, 5);
    for (int pass = 0; pass < 3; ++pass) {
        for (int i = 0; i < 20000; ++i) {
            const Vec3 p = bounds.lo + bounds.extent() * Vec3(rng.next_float(), rng.next_float(), rng.next_float());
            Vec3 d = lobe + Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) * 0.05f;
            t.record(p, d / norm(d), 1.0);
        }
        t.update(1);
    }
    return t;
}

TEST(PathGuiding, UnbiasedWithAWrongGuide) {
    const std::string path = write_temp_scene(lit_room_xml());
    auto scene = load_scene(path);
    const BlockMoments nee = block_moments(path, "path", Options(), 6, 64, 101);
    // Into the floor (the guide's share of the samples is then mostly wasted), and away from the light.
    // Most samples from the wrong guide (the default leaves it a quarter), so that its errors would show.
    OptionMap guided = kGuided;
    guided["guiding_bsdf_fraction"] = "0.25";
    const SDTree down = cone_guide(scene->bounds(), Vec3(0, -1, 0));
    ASSERT_TRUE(down.can_guide(down.leaf_at(Vec3(0.f, 1.f, 0.f))));
    ASSERT_LT(down.pdf(down.leaf_at(Vec3(0.f, 1.f, 0.f)), Vec3(0, 1, 0)), 1e-3f) << "nothing guided upward";
    // Twelve seeds: NEE's MIS weight takes the BSDF's own density (sample_guided), so a sample of this guide
    // that finds the light by the BSDF's quarter weighs up to four times the BSDF's own sample, and the
    // heavier tail needs more seeds for its variance (six gave z = 5.03 in one block, 24 pass).
    expect_same_image(nee, guided_moments(path, guided, 12, 64, 404, &down), "guide pointing down");
    const SDTree back = cone_guide(scene->bounds(), Vec3(0, 0, 1));
    expect_same_image(nee, guided_moments(path, guided, 6, 64, 505, &back), "guide pointing out of the room");
    // A guide learned on another scene (its cube elsewhere: points map to its nearest leaves).
    auto other_scene = load_scene(write_temp_scene(kGlossyRoomXml));
    auto other = make_integrator("path", with_scene_options(*other_scene, Options(kGuided)));
    RenderJob job;
    job.spp = 16;
    render(*other_scene, *other, job);
    const SDTree learned_elsewhere = *dynamic_cast<const PathIntegrator &>(*other).guide();
    expect_same_image(nee, guided_moments(path, guided, 6, 64, 606, &learned_elsewhere), "guide of another scene");
}

TEST(PathGuiding, SameImageToTheBitForASeedAndThreadCount) {
    const std::string path = write_temp_scene(lit_room_xml());
    auto render_once = [&](uint64_t seed) {
        auto scene = load_scene(path);
        auto integrator = make_integrator("path", with_scene_options(*scene, Options(kGuided)));
        RenderJob job;
        job.spp = 24;
        job.seed = seed;
        job.threads = 4;
        return render(*scene, *integrator, job).image;
    };
    const Image a = render_once(9), b = render_once(9), c = render_once(10);
    ASSERT_EQ(a.data.size(), b.data.size());
    EXPECT_TRUE(a.data == b.data) << "the same seed and thread count";
    EXPECT_FALSE(a.data == c.data) << "another seed";
}

// The state carries the tree (checkpoints, distributed rounds); merged states hold what each render learned.
TEST(PathGuiding, StateCarriesAndMergesTheTree) {
    const std::string path = write_temp_scene(lit_room_xml());
    auto learn = [&](uint64_t seed, int spp) {
        auto scene = load_scene(path);
        auto integrator = make_integrator("path", with_scene_options(*scene, Options(kGuided)));
        RenderJob job;
        job.spp = spp;
        job.seed = seed;
        render(*scene, *integrator, job);
        return std::pair{integrator->save_state(), SDTree(*dynamic_cast<const PathIntegrator &>(*integrator).guide())};
    };
    const auto [state_a, tree_a] = learn(1, 8);
    const auto [state_b, tree_b] = learn(2, 16);
    auto scene = load_scene(path);
    auto fresh = make_integrator("path", with_scene_options(*scene, Options(kGuided)));
    fresh->prepare(*scene);
    fresh->restore_state(*scene, state_a);
    EXPECT_TRUE(*dynamic_cast<const PathIntegrator &>(*fresh).guide() == tree_a);
    EXPECT_EQ(fresh->save_state(), state_a);

    const std::string merged = fresh->merge_states(std::string(), {state_a, state_b});
    fresh->restore_state(*scene, merged);
    const SDTree *trees[] = {&tree_a, &tree_b};
    EXPECT_TRUE(*dynamic_cast<const PathIntegrator &>(*fresh).guide() == SDTree::merge(trees));
    EXPECT_EQ(fresh->merge_states(state_a, {}), state_a);
    // An unguided state is refused by a guided integrator, not misread.
    auto plain = make_integrator("path", with_scene_options(*scene, Options(OptionMap{{"shadow_rays", "neepp"}})));
    plain->prepare(*scene);
    RenderJob job;
    job.spp = 2;
    render(*scene, *plain, job);
    EXPECT_THROW(fresh->restore_state(*scene, plain->save_state()), std::runtime_error);
}

// The guide's sampling at a vertex against its density, folded onto one side (a surface that only
// reflects) and not: chi-square on the 128 x 128 grid of the cylindrical mapping around z, whose cells the
// quadtree's (max_depth 7) and their mirror images across z = 0 align with, so each bin's expected count
// is its density times its area exactly; the density integrates to one, and is zero behind the surface.
TEST(PathGuiding, ChiSquareOfTheVertexGuideAgainstItsDensity) {
    BBox box;
    box.expand(Vec3(-1.f));
    box.expand(Vec3(1.f));
    SDTreeOptions o;
    o.max_depth = 7;
    SDTree tree(box, o);
    PCG32 rng(1, 1);
    for (int pass = 0; pass < 3; ++pass) {
        for (int i = 0; i < 30000; ++i) {
            Vec3 d(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
            if (rng.next_float() < 0.6f) d = Vec3(0.3f, -0.2f, -0.8f) + d * 0.2f;  // mostly from below
            tree.record(Vec3(0.f), d / norm(d), 1.0);
        }
        tree.update(1);
    }
    for (bool fold : {false, true}) {
        VertexGuide g;
        g.tree = &tree;
        g.leaf = tree.leaf_at(Vec3(0.f));
        g.bsdf_fraction = 0.5f;
        g.fold = fold;
        g.up = Vec3(0, 0, 1);
        const int n = 128, samples = 1000000;
        const double two_pi = 6.283185307179586;
        std::vector<double> observed(size_t(n) * n, 0.0), expected(size_t(n) * n, 0.0);
        PCG32 r(2, 2);
        for (int i = 0; i < samples; ++i) {
            const Vec3 d = g.sample(0.f, 0.f, r.next_2d());
            if (fold) ASSERT_GE(d.z, 0.f);
            const double c = std::clamp((double(d.z) + 1) / 2, 0.0, std::nextafter(1.0, 0.0));
            double phi = std::atan2(double(d.y), double(d.x));
            if (phi < 0) phi += two_pi;
            observed[size_t(std::min(phi / two_pi, std::nextafter(1.0, 0.0)) * n) * n + size_t(c * n)] += 1;
        }
        double integral = 0, behind = 0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double phi = two_pi * (y + 0.5) / n, ct = 2 * (x + 0.5) / n - 1, st = std::sqrt(1 - ct * ct);
                const Vec3 d(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct));
                const double mass = double(g.guide_pdf(d)) * 4 * 3.141592653589793 / (double(n) * n);
                expected[size_t(y) * n + x] = mass * samples;
                integral += mass;
                if (ct < 0) behind += mass;
            }
        EXPECT_NEAR(integral, 1.0, 1e-5) << fold;
        if (fold) EXPECT_EQ(behind, 0.0);
        else EXPECT_GT(behind, 0.3) << "the tree learned light from below";
        const test::Chi2Result res = test::chi2_from_histograms(observed, expected);
        EXPECT_TRUE(res.error.empty()) << res.error;
        EXPECT_GT(res.p_value, 0.01 / 2) << fold << " " << res.describe();
    }
}


// The visibility map's guide (guiding=map): learned as the render goes, mostly sampled, without NEE, and
// deliberately wrong, the image is plain NEE's; the same to the bit for a seed and thread count; the state
// carries its totals and merges what several renders added.
const OptionMap kMapGuided = {{"guiding", "map"}};

TEST(MapGuiding, OptionKeepsAMapAndLearns) {
    auto scene = load_scene(write_temp_scene(lit_room_xml()));
    auto integrator = make_integrator("path", with_scene_options(*scene, Options(kMapGuided)));
    EXPECT_EQ(integrator->describe()["guiding"], "map");
    RenderJob job;
    job.spp = 16;
    job.seed = 3;
    render(*scene, *integrator, job);
    const auto &pi = dynamic_cast<const PathIntegrator &>(*integrator);
    ASSERT_NE(pi.shadow_rays().visibility_map(), nullptr) << "the guide's prior reads the map";
    const MapGuide *guide = pi.map_guide();
    ASSERT_NE(guide, nullptr);
    EXPECT_GT(guide->records(), 1000u);
    EXPECT_GT(guide->table_count(), 10u);
    EXPECT_NE(guide->table_at(Vec3(0.f, 0.05f, 0.f)), nullptr) << "the floor under the camera";
    EXPECT_EQ(integrator->statistics()["guiding"]["kind"], "map");
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"guiding", "map"}, {"neepp", "auto"}})), std::invalid_argument);
}

// Twelve seeds where the guide draws most directions or NEE is off: on the glossy room the map's guide is
// far broader than the glossy lobes, so a path whose directions came from the guide carries up to
// 1 / bsdf_fraction times the BSDF's weight at each bounce, and the rare such path that finds the light is
// a firefly. 800 seeds of the glossy room at bsdf_fraction 0.1 put every block's mean within 2.8 standard
// errors of NEE's (block 8: +5 %, its median -25 % and its largest sample 60 times its mean), where 200 had
// put block 8 at -16 %, z = -5.4: a heavy tail, not a bias.
TEST(MapGuiding, UnbiasedAgainstPlainNee) {
    const std::vector<std::pair<std::string, std::string>> scenes = {{"lit room", lit_room_xml()},
                                                                      {"glossy room", kGlossyRoomXml}};
    for (const auto &[name, xml] : scenes) {
        const std::string path = write_temp_scene(xml);
        const BlockMoments nee = block_moments(path, "path", Options(), 6, 64, 101);
        expect_same_image(nee, guided_moments(path, kMapGuided, 6, 64, 212, nullptr), name + " map-guided");
        OptionMap mostly_guide = kMapGuided;
        mostly_guide["guiding_bsdf_fraction"] = "0.25";
        mostly_guide["shadow_rays"] = "neepp";
        expect_same_image(nee, guided_moments(path, mostly_guide, 12, 64, 262, nullptr),
                          name + " map-guided, bsdf_fraction 0.25, NEE++ shadow rays");
        OptionMap bsdf_only = kMapGuided;
        bsdf_only["nee"] = "false";
        expect_same_image(nee, guided_moments(path, bsdf_only, 12, 64, 313, nullptr), name + " map-guided, nee=false");
    }
}

TEST(MapGuiding, UnbiasedWithAWrongGuide) {
    const std::string path = write_temp_scene(lit_room_xml());
    auto scene = load_scene(path);
    const BlockMoments nee = block_moments(path, "path", Options(), 6, 64, 101);
    auto probe = make_integrator("path", with_scene_options(*scene, Options(kMapGuided)));
    probe->prepare(*scene);
    const VoxelGrid &grid = *dynamic_cast<const PathIntegrator &>(*probe).shadow_rays().voxel_grid();
    // Every voxel learned that all its flux comes from one voxel under the floor: most guided directions
    // then go down into the floor, and none toward the light or the sky.
    MapGuide wrong(grid);
    PCG32 rng(8, 8);
    const uint32_t below = grid.voxel_of(Vec3(0.3f, -0.01f, -0.2f));
    for (int i = 0; i < 200000; ++i) {
        const Vec3 p = grid.bounds().lo + grid.bounds().extent() * Vec3(rng.next_float(), rng.next_float(), rng.next_float());
        wrong.record(p, below, 1.0, 1.0, Vec3(0.3f, -0.01f, -0.2f));
    }
    wrong.update(nullptr);
    OptionMap guided = kMapGuided;
    guided["guiding_bsdf_fraction"] = "0.25";
    const std::string saved = wrong.save();
    expect_same_image(nee, guided_moments(path, guided, 12, 64, 414, nullptr, &saved), "map guide pointing down");
}

TEST(MapGuiding, SameImageToTheBitForASeedAndThreadCount) {
    const std::string path = write_temp_scene(lit_room_xml());
    auto render_once = [&](uint64_t seed, const char *form) {
        auto scene = load_scene(path);
        OptionMap o = kMapGuided;
        o["form"] = form;
        auto integrator = make_integrator("path", with_scene_options(*scene, Options(o)));
        RenderJob job;
        job.spp = 24;
        job.seed = seed;
        job.threads = 4;
        return render(*scene, *integrator, job).image;
    };
    for (const char *form : {"fast", "reference"}) {
        const Image a = render_once(9, form), b = render_once(9, form), c = render_once(10, form);
        ASSERT_EQ(a.data.size(), b.data.size());
        EXPECT_TRUE(a.data == b.data) << form << ": the same seed and thread count";
        EXPECT_FALSE(a.data == c.data) << form << ": another seed";
    }
}

TEST(MapGuiding, StateCarriesAndMergesTheTotals) {
    const std::string path = write_temp_scene(lit_room_xml());
    auto scene = load_scene(path);
    auto learn = [&](uint64_t seed, int spp) {
        auto integrator = make_integrator("path", with_scene_options(*scene, Options(kMapGuided)));
        RenderJob job;
        job.spp = spp;
        job.seed = seed;
        render(*scene, *integrator, job);
        return std::pair{integrator->save_state(), dynamic_cast<const PathIntegrator &>(*integrator).map_guide()->save()};
    };
    const auto [state_a, guide_a] = learn(1, 8);
    const auto [state_b, guide_b] = learn(2, 16);
    auto fresh = make_integrator("path", with_scene_options(*scene, Options(kMapGuided)));
    fresh->prepare(*scene);
    fresh->restore_state(*scene, state_a);
    EXPECT_EQ(dynamic_cast<const PathIntegrator &>(*fresh).map_guide()->save(), guide_a);
    EXPECT_EQ(fresh->save_state(), state_a);
    // Two renders from nothing: the merged totals are both renders' records.
    fresh->restore_state(*scene, fresh->merge_states(std::string(), {state_a, state_b}));
    const std::string both[] = {guide_a, guide_b};
    EXPECT_EQ(dynamic_cast<const PathIntegrator &>(*fresh).map_guide()->save(), MapGuide::merge("", both));
    const VoxelGrid &grid = *dynamic_cast<const PathIntegrator &>(*fresh).shadow_rays().voxel_grid();
    MapGuide a(grid), b(grid);
    a.load(guide_a);
    b.load(guide_b);
    EXPECT_EQ(dynamic_cast<const PathIntegrator &>(*fresh).map_guide()->records(), a.records() + b.records());
    // An sdtree state is refused by a map-guided integrator, not misread.
    auto tree = make_integrator("path", with_scene_options(*scene, Options(kGuided)));
    RenderJob job;
    job.spp = 2;
    render(*scene, *tree, job);
    EXPECT_THROW(fresh->restore_state(*scene, tree->save_state()), std::runtime_error);
}



// Both guides (guiding=sdtree+map): three strategies of the one-sample MIS. Each guide's sampling is
// chi-square tested against its density on its own (above, and tests/guiding/test_map_guide.cpp); here the
// mixture: u_pick below the tree's share draws the tree's direction for (u1, u2), above it the map guide's
// for u_pick rescaled, and the density is the two weighed by their shares, integrating to one.
const OptionMap kBothGuided = {{"guiding", "sdtree+map"}};

TEST(BothGuides, TheMixtureDrawsEachGuideByItsShare) {
    // A vertex on the lit room's floor (diffuse), and both guides learned at it.
    auto scene = load_scene(write_temp_scene(lit_room_xml()));
    SurfaceInteraction si;
    ASSERT_TRUE(scene->intersect(Ray{Vec3(0.1f, 1.f, 0.05f), Vec3(0, -1, 0)}, si));
    const Vec3 p = si.p;
    BBox box;
    box.expand(Vec3(-1.f));
    box.expand(Vec3(1.f));
    SDTreeOptions o;
    o.max_depth = 7;
    SDTree tree(box, o);
    const VoxelGrid grid(box, 4);
    MapGuide map(grid);
    PCG32 rng(3, 3);
    const Vec3 lamp(0.6f, 0.9f, -0.7f), corner(-0.9f, 0.9f, 0.9f);
    for (int pass = 0; pass < 2; ++pass) {
        for (int i = 0; i < 30000; ++i) {
            Vec3 d(2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
            if (rng.next_float() < 0.6f) d = Vec3(0.3f, 0.8f, -0.2f) + d * 0.2f;
            tree.record(p, d / norm(d), 1.0);
            map.record(p, grid.voxel_of(lamp), 2.0, 1.0, lamp);
            if (i % 3 == 0) map.record(p, grid.voxel_of(corner), 1.0, 1.0, corner);
        }
        tree.update(1);
        map.update(nullptr);
    }
    const float share = 0.3f;
    const VertexGuide g = guide_at(&tree, &map, true, si, 0.5f, share);
    ASSERT_TRUE(g.tree && g.table) << "both guide here";
    EXPECT_FLOAT_EQ(g.tree_share, share);
    const VertexGuide tree_only = guide_at(&tree, nullptr, true, si, 0.5f, share);
    const VertexGuide map_only = guide_at(nullptr, &map, true, si, 0.5f, share);
    EXPECT_TRUE(tree_only.tree && !tree_only.table && tree_only.tree_share == 1.f);
    EXPECT_TRUE(!map_only.tree && map_only.table && map_only.tree_share == 0.f);
    EXPECT_FALSE(guide_at(&tree, &map, true, si, 0.5f, 0.f).tree) << "a share of 0: the map's guide alone";
    EXPECT_FALSE(guide_at(&tree, &map, true, si, 0.5f, 1.f).table) << "a share of 1: the tree alone";
    PCG32 r(4, 4);
    int from_tree = 0;
    for (int i = 0; i < 2000; ++i) {
        const float u_pick = r.next_float(), u1 = r.next_float();
        const Vec2 u2 = r.next_2d();
        const Vec3 d = g.raw_sample(u_pick, u1, u2);
        if (u_pick < share) {
            ++from_tree;
            EXPECT_EQ(d, tree_only.raw_sample(0.f, u1, u2));
        } else {
            EXPECT_EQ(d, map_only.raw_sample(std::min((u_pick - share) / (1.f - share), kOneMinusEpsilon), u1, u2));
        }
        const Vec3 e = r.next_float() < 0.5f ? d : Vec3(r.next_float() - 0.5f, r.next_float() - 0.5f, r.next_float() - 0.5f);
        const Vec3 dir = e / norm(e);
        EXPECT_NEAR(g.raw_pdf(dir), share * tree_only.raw_pdf(dir) + (1 - share) * map_only.raw_pdf(dir),
                    1e-5f * (1 + g.raw_pdf(dir)));
    }
    EXPECT_GT(from_tree, 500);
    // The mixture's density integrates to one over the sphere (a 512 x 512 grid of equal solid angle; the map
    // guide's box densities are not aligned to it, hence the tolerance).
    double integral = 0;
    const int n = 512;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double phi = 6.283185307179586 * (y + 0.5) / n, ct = 2 * (x + 0.5) / n - 1, st = std::sqrt(1 - ct * ct);
            integral += double(g.raw_pdf(Vec3(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct))));
        }
    EXPECT_NEAR(integral * 4 * 3.141592653589793 / (double(n) * n), 1.0, 0.02);
}

TEST(BothGuides, OptionKeepsBothAndEachLearns) {
    auto scene = load_scene(write_temp_scene(lit_room_xml()));
    auto integrator = make_integrator("path", with_scene_options(*scene, Options(kBothGuided)));
    EXPECT_EQ(integrator->describe()["guiding"], "sdtree+map");
    RenderJob job;
    job.spp = 16;
    job.seed = 3;
    render(*scene, *integrator, job);
    const auto &pi = dynamic_cast<const PathIntegrator &>(*integrator);
    ASSERT_NE(pi.guide(), nullptr);
    ASSERT_NE(pi.map_guide(), nullptr);
    EXPECT_GT(pi.map_guide()->records(), 1000u);
    EXPECT_EQ(integrator->statistics()["guiding"]["kind"], "sdtree+map");
    EXPECT_EQ(integrator->statistics()["guiding"]["map"]["kind"], "map");
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"guiding", "sdtree+map"}, {"guiding_tree_share", "1.5"}})),
                 std::invalid_argument);
    EXPECT_THROW(make_integrator("path", Options(OptionMap{{"guiding", "sdtree+mop"}})), std::invalid_argument);
}

// As MapGuiding.UnbiasedAgainstPlainNee, with the two guides sharing the guided directions (a quarter or
// most of them to the tree).
TEST(BothGuides, UnbiasedAgainstPlainNee) {
    const std::vector<std::pair<std::string, std::string>> scenes = {{"lit room", lit_room_xml()},
                                                                      {"glossy room", kGlossyRoomXml}};
    for (const auto &[name, xml] : scenes) {
        const std::string path = write_temp_scene(xml);
        const BlockMoments nee = block_moments(path, "path", Options(), 6, 64, 101);
        expect_same_image(nee, guided_moments(path, kBothGuided, 6, 64, 717, nullptr), name + " both guides");
        OptionMap mostly_guide = kBothGuided;
        mostly_guide["guiding_bsdf_fraction"] = "0.25";
        mostly_guide["guiding_tree_share"] = "0.75";
        mostly_guide["shadow_rays"] = "neepp";
        expect_same_image(nee, guided_moments(path, mostly_guide, 12, 64, 767, nullptr),
                          name + " both guides, bsdf_fraction 0.25, tree share 0.75, NEE++ shadow rays");
    }
}

TEST(BothGuides, SameImageToTheBitAndStateCarriesBoth) {
    const std::string path = write_temp_scene(lit_room_xml());
    auto scene = load_scene(path);
    auto render_once = [&](uint64_t seed, const char *form, std::string *state) {
        OptionMap o = kBothGuided;
        o["form"] = form;
        auto integrator = make_integrator("path", with_scene_options(*scene, Options(o)));
        RenderJob job;
        job.spp = 16;
        job.seed = seed;
        job.threads = 4;
        Image image = render(*scene, *integrator, job).image;
        if (state) *state = integrator->save_state();
        return image;
    };
    for (const char *form : {"fast", "reference"}) {
        const Image a = render_once(9, form, nullptr), b = render_once(9, form, nullptr);
        EXPECT_TRUE(a.data == b.data) << form << ": the same seed and thread count";
    }
    std::string state_a, state_b;
    render_once(1, "fast", &state_a);
    render_once(2, "fast", &state_b);
    auto fresh = make_integrator("path", with_scene_options(*scene, Options(kBothGuided)));
    fresh->prepare(*scene);
    fresh->restore_state(*scene, state_a);
    EXPECT_EQ(fresh->save_state(), state_a) << "the tree and the map guide's totals both come back";
    fresh->restore_state(*scene, fresh->merge_states(std::string(), {state_a, state_b}));
    const auto &pi = dynamic_cast<const PathIntegrator &>(*fresh);
    auto guides_of = [&](const std::string &state) {
        auto one = make_integrator("path", with_scene_options(*scene, Options(kBothGuided)));
        one->prepare(*scene);
        one->restore_state(*scene, state);
        const auto &p = dynamic_cast<const PathIntegrator &>(*one);
        return std::pair{*p.guide(), p.map_guide()->records()};
    };
    const auto [tree_a, records_a] = guides_of(state_a);
    const auto [tree_b, records_b] = guides_of(state_b);
    const SDTree *trees[] = {&tree_a, &tree_b};
    EXPECT_TRUE(*pi.guide() == SDTree::merge(trees));
    EXPECT_EQ(pi.map_guide()->records(), records_a + records_b);
}


// The path state's frames: G3 (shadow, tree, light, map guide) round-trips; the earlier G2 (shadow, guide,
// light) and G1 (shadow, guide) still read, a G2 guide going to the map guide's part when the integrator
// guides by the map (where guiding=map kept it then); anything else is refused.
TEST(PathStateFrames, ReadsEveryLayoutItWrote) {
    PathState s;
    s.shadow = "shadow bytes";
    s.guide = "tree";
    s.guide_spp = 24;
    s.light = "light";
    s.map_guide = "map guide";
    const PathState back = PathState::decode(s.encode(true), true);
    EXPECT_EQ(back.shadow, s.shadow);
    EXPECT_EQ(back.guide, s.guide);
    EXPECT_EQ(back.guide_spp, 24);
    EXPECT_EQ(back.light, s.light);
    EXPECT_EQ(back.map_guide, s.map_guide);
    EXPECT_EQ(PathState::decode(s.encode(false), false).shadow, s.shadow) << "unframed: the shadow state alone";
    auto frame = [](const char *magic, const std::vector<std::string> &parts) {
        std::string out(magic, 8);
        const int32_t spp = 7;
        out.append(reinterpret_cast<const char *>(&spp), sizeof spp);
        for (const std::string &part : parts) {
            const uint64_t n = part.size();
            out.append(reinterpret_cast<const char *>(&n), sizeof n);
            out += part;
        }
        return out;
    };
    const std::string g2 = frame("NEEPPPG2", {"shadow", "saved guide", "light"});
    const PathState tree_guided = PathState::decode(g2, true, false);
    EXPECT_EQ(tree_guided.guide, "saved guide");
    EXPECT_TRUE(tree_guided.map_guide.empty());
    EXPECT_EQ(tree_guided.light, "light");
    EXPECT_EQ(tree_guided.guide_spp, 7);
    const PathState map_guided = PathState::decode(g2, true, true);
    EXPECT_TRUE(map_guided.guide.empty());
    EXPECT_EQ(map_guided.map_guide, "saved guide");
    const PathState g1 = PathState::decode(frame("NEEPPPG1", {"shadow", "saved guide"}), true, false);
    EXPECT_EQ(g1.shadow, "shadow");
    EXPECT_EQ(g1.guide, "saved guide");
    EXPECT_TRUE(g1.light.empty());
    EXPECT_THROW(PathState::decode(frame("NEEPPPG9", {"shadow", "guide", "light"}), true), std::runtime_error);
    EXPECT_THROW(PathState::decode(g2 + "x", true), std::runtime_error) << "trailing bytes";
    EXPECT_THROW(PathState::decode(g2.substr(0, g2.size() - 2), true), std::runtime_error) << "truncated";
}

}  // namespace
