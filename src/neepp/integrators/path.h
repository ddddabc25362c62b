// Unidirectional path tracing with Mitsuba 3's `path` semantics: next event estimation combined with BSDF
// sampling by the power heuristic, Russian roulette from rr_depth, max_depth counting path vertices
// (1 = emitters seen directly, 2 = direct lighting, -1 = unbounded). With nee=false it is the paper's
// "Path" baseline (BSDF sampling only, lights found by chance).
#pragma once
#include <memory>
#include "neepp/base/integrator.h"
#include "neepp/base/light_sampler.h"
#include "neepp/guiding/map_guide.h"
#include "neepp/guiding/sd_tree.h"
#include "neepp/light_selection/resampling.h"
#include "neepp/light_selection/within_light_sampling.h"
#include "neepp/visibility/shadow_ray_tester.h"

namespace neepp {

struct PathOptions {
    int max_depth = -1;
    int rr_depth = 5;
    bool hide_emitters = false;
    bool nee = true;
    std::string light_sampler = "bvh";  // pbrt-v4's default too; the best of the non-NEE++ choices (docs/neepp.md)
    std::string within_light = "own";  // how a point on the chosen light is sampled (WithinLightSampling)
    std::string area_light_sampling = "area";  // area or solid-angle (light_selection/solid_angle_sampling.h)
    int voxels = 16;  // grid of the spatial light sampler when NEE++ keeps no map (else the map's grid)
    // Resampled NEE (light_selection/resampling.h): ris light-sample candidates per vertex, one chosen by
    // f·Le·max(√Ṽ, ris_floor) for the shadow ray (1 = plain NEE), at the path's first ris_depth vertices
    // (-1: all) and plain NEE beyond. By default at the camera's first hit only: there a candidate costs
    // what it costs deeper, and it buys the most (deeper vertices' noise is mostly the path's own): the
    // most efficient depth on most scenes measured (docs/neepp.md).
    static constexpr int kMaxCandidates = 32;
    int ris = 1;
    float ris_floor = 0.05f;  // as q_min: a wrong map costs at most a factor 1/ris_floor in a sample's weight
    int ris_depth = 1;
    // Which form renders: fast (PathBatch, the default) or reference (PathIntegrator::Li, one path at a
    // time: the definition, slower).
    bool reference = false;
    // Mitsuba 3's volpath (volpath.cpp): paths through participating media, surfaces that are null to the
    // path (null, a mask's clear part, a thin dielectric's transmission) crossed without counting a bounce,
    // and shadow rays that pass such surfaces and media with their transmittance. Reference form only.
    bool volumetric = false;
    // Path guiding (path_guiding.h): at vertices without a delta BSDF part the next direction is drawn by
    // one-sample MIS between the BSDF (guiding_bsdf_fraction of the samples) and a guide learned from the
    // passes before: "sdtree" (practical path guiding's SD-tree), "map" (the visibility map's guide,
    // map_guide.h) or "sdtree+map" (both, a third strategy of the one-sample MIS: the guide's share split
    // guiding_tree_share to the tree where both guide; each learns from every guided vertex); "none"
    // guides nothing. NEE stays for direct light. Both forms render it.
    std::string guiding = "none";
    bool guides_by_tree() const { return guiding == "sdtree" || guiding == "sdtree+map"; }
    bool guides_by_map() const { return guiding == "map" || guiding == "sdtree+map"; }
    // guiding=sdtree+map: the tree's share of the guide's directions where both guide (the map's guide has
    // a table from the first pass on, the tree a leaf that guides only once it has learned).
    float guiding_tree_share = 0.5f;
    // PPG's is 0.5; with NEE on classroom and living-room (docs/performance.md) 0.75 measured less noisy
    // (relVar 0.94x NEE's against 0.98-1.08x) and 0.9 no less noisy than 0.75.
    float guiding_bsdf_fraction = 0.75f;
    // The SD-tree's spatial threshold c (SDTreeOptions::spatial_threshold); 0: scaled to the image
    // (sd_tree.h).
    double guiding_spatial_threshold = 12000;
    // What a guided vertex's record holds: all the radiance its direction brought (true), or that less the
    // emission the direction found directly (false: the light next event estimation also samples).
    bool guiding_learn_direct = true;
};

class PathBatch;
struct VertexGuide;
class GuideRecorder;

class PathIntegrator final : public RayIntegrator {
public:
    explicit PathIntegrator(PathOptions options, std::unique_ptr<ShadowRayTester> shadow);
    ~PathIntegrator() override;
    void prepare(const Scene &scene) override;
    void end_pass(const Scene &scene, const PassStatistics &pass) override;
    // While the shadow-ray policy reads or updates its visibility map (which the light sampler may read too),
    // the light sampler learns from NEE's samples, or the guide learns.
    bool learns_between_passes() const override {
        return shadow_->learns_between_passes() || (guide_ && guide_learns_) || learner_;
    }
    // What the shadow-ray component has learned (NEE++'s map, phase, calibration), and with guiding the
    // SD-tree the next pass samples (path_state.cpp).
    std::string save_state() const override;
    std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const override;
    void restore_state(const Scene &scene, const std::string &state) override;
    nlohmann::json statistics() const override;
    // The reference form: one path, one vertex at a time, every choice made where it reads (path.cpp).
    // It defines what the path tracer computes; the fast form below is tested against it.
    Color Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters) const override;
    // The fast form (PathBatch, path_batch.h): the batch's paths advance in lockstep, stage by stage, so
    // that cache prefetches and packets of rays pay. Same random numbers in the same order per path as Li.
    // None with form=reference: the render loop then calls Li.
    const RayBatch *batch() const override;
    nlohmann::json describe() const override;
    const PathOptions &options() const { return options_; }
    const ShadowRayTester &shadow_rays() const { return *shadow_; }
    ShadowRayTester &shadow_rays() { return *shadow_; }
    // The light choice NEE makes (null before prepare()), for tools that show its distribution.
    const LightSampler *light_sampler() const { return light_sampler_.get(); }
    // guiding=sdtree: the SD-tree the coming pass samples (null before prepare()).
    const SDTree *guide() const { return guide_.get(); }
    // For tests: guide by this tree from now on, and never change it (no records, no updates), e.g. a tree
    // that is deliberately wrong for the scene. prepare() keeps it.
    void install_guide(std::unique_ptr<SDTree> tree) {
        guide_ = std::move(tree);
        guide_learns_ = false;
    }
    // guiding=map: the map guide the coming pass samples (null before prepare()), and for tests, one to
    // guide by from now on that never changes.
    const MapGuide *map_guide() const { return map_guide_.get(); }
    void install_map_guide(std::unique_ptr<MapGuide> guide) {
        map_guide_ = std::move(guide);
        guide_learns_ = false;
    }

private:
    friend class PathBatch;
    struct LightCandidate;
    // The light-selection context of a scattering vertex reached along direction d: its normal turned
    // toward the side the path arrived from (the side it gathers light on), so that orientation-aware
    // samplers see which way it faces. Made once per vertex and used both where lights are sampled and
    // where MIS asks for the pmf, so the two agree.
    static LightSampleContext light_context(const SurfaceInteraction &si, const Vec3 &d) {
        return {si.p, dot(d, si.n) > 0 ? -si.n : si.n};
    }
    // Next event estimation at a scattering vertex (pbrt-v4's SampleLd): a light sample, or with ris > 1
    // one of M resampled ones, tested by the shadow-ray component; the contribution already multiplied by
    // the path throughput beta, which contribution-aware shadow-ray policies need to see.
    // With a guide, the BSDF strategy's density in the MIS weight is still the BSDF's own (sample_guided).
    Color sample_direct(const Scene &scene, const SurfaceInteraction &si, const LightSampleContext &ctx,
                        const Color &beta, int M, Sampler &sampler, RenderCounters &counters) const;
    // MIS weight for emission found by a BSDF-sampled ray leaving prev (pdf prev_pdf) toward light.
    float emission_weight(const Light &light, const LightSampleContext &prev, const DirectionSample &ds,
                          float prev_pdf) const;
    // Russian roulette on the throughput (times eta², so that refraction does not trigger it), Mitsuba's
    // rule: false ends the path; a survivor's beta is divided by its survival probability.
    static bool survives_roulette(Color &beta, float eta, Sampler &sampler);
    // Light-sample candidates at a vertex of this depth: options_.ris at the first ris_depth, else 1.
    int candidates_at(int depth) const {
        return options_.ris_depth < 0 || depth < options_.ris_depth ? options_.ris : 1;
    }
    bool resampling() const { return options_.ris > 1; }
    // Whether the state needs PathState's frame: guiding, or a light sampler that learns.
    bool framed_state() const;
    // The volumetric form (volpath.cpp): Li when options_.volumetric.
    struct ScatteringPoint;
    Color Li_volumetric(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters) const;
    Color sample_direct_volumetric(const Scene &scene, const ScatteringPoint &v, const Color &beta, int channel,
                                   Sampler &sampler, RenderCounters &counters) const;
    // The map's share of the resampling target, from the map the coming pass reads.
    void refresh_resampling();

    PathOptions options_;
    std::unique_ptr<ShadowRayTester> shadow_;
    const ShadowRayTester *queries_ = nullptr;  // shadow_->query_tester() for the coming pass
    std::unique_ptr<LightSampler> light_sampler_;
    LightSelectionLearner *learner_ = nullptr;  // light_sampler_'s, when it learns from NEE's samples
    std::unique_ptr<PathBatch> batch_;
    WithinLightSampling within_light_;
    ResamplingVisibility resampling_visibility_;
    // The guide at a vertex (none, the tree's or the map's), and a path's records into the learning one.
    VertexGuide vertex_guide(const SurfaceInteraction &si) const;
    void commit_guide(const GuideRecorder &recorder, const Color &L) const;
    std::unique_ptr<SDTree> guide_;  // guiding=sdtree; records from every thread (SDTree::record is thread-safe)
    std::unique_ptr<MapGuide> map_guide_;  // guiding=map; likewise
    bool guide_learns_ = true;
    int guide_spp_ = 0;              // samples per pixel the guide has seen, for the size of each pass
};

}  // namespace neepp
