// Unidirectional path tracing with Mitsuba 3's `path` semantics: next event estimation combined with BSDF
// sampling by the power heuristic, Russian roulette from rr_depth, max_depth counting path vertices
// (1 = emitters seen directly, 2 = direct lighting, -1 = unbounded). With nee=false it is the paper's
// "Path" baseline (BSDF sampling only, lights found by chance).
#pragma once
#include <memory>
#include "neepp/integrators/integrator.h"
#include "neepp/light_selection/resampling.h"
#include "neepp/light_selection/within_light_sampling.h"
#include "neepp/lights/light_sampler.h"
#include "neepp/visibility/shadow_ray_tester.h"

namespace neepp {

class LightSampleLanes;

struct PathOptions {
    int max_depth = -1;
    int rr_depth = 5;
    bool hide_emitters = false;
    bool nee = true;
    std::string light_sampler = "bvh";  // pbrt-v4's default too; measured best of the non-NEE++ choices (docs/neepp.md)
    std::string within_light = "own";  // how a point on the chosen light is sampled (WithinLightSampling)
    int voxels = 16;  // grid of the spatial light sampler when NEE++ keeps no map (else the map's grid)
    // Resampled NEE (light_selection/resampling.h): ris light-sample candidates per vertex, one chosen by
    // f·Le·max(√Ṽ, ris_floor) for the shadow ray (1 = plain NEE), at the path's first ris_depth vertices
    // (-1: all) and plain NEE beyond. By default at the camera's first hit only: there a candidate costs
    // what it costs deeper, and it buys the most (deeper vertices' noise is mostly the path's own), so it
    // was the most efficient depth on six of the seven scenes measured (docs/neepp.md).
    static constexpr int kMaxCandidates = 32;
    int ris = 1;
    float ris_floor = 0.05f;  // as q_min: a wrong map costs at most a factor 1/ris_floor in a sample's weight
    int ris_depth = 1;
};

class PathIntegrator final : public Integrator {
public:
    explicit PathIntegrator(PathOptions options, std::unique_ptr<ShadowRayTester> shadow);
    void prepare(const Scene &scene) override;
    void end_pass(const Scene &scene, const PassStatistics &pass) override;
    // While the shadow-ray policy reads or updates its visibility map (which the light sampler may read too).
    bool learns_between_passes() const override { return shadow_->learns_between_passes(); }
    // What the shadow-ray component has learned (NEE++'s map, phase, calibration).
    std::string save_state() const override { return shadow_->save_state(); }
    std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const override {
        return shadow_->merge_states(base, learned);
    }
    void restore_state(const Scene &scene, const std::string &state) override;
    nlohmann::json statistics() const override;
    Color Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters) const override;
    // Paths of a batch advance in lockstep, one bounce at a time and stage by stage, each stage issuing
    // cache prefetches that the next stage, reached after the other paths' work, finds complete: without
    // it the render waits on misses (mesh data, textures, environment-map tables) as long as it traces.
    // Same random numbers in the same order per path as Li, so the same result to the bit.
    void Li_batch(const Scene &scene, std::span<const Ray> rays, std::span<Sampler *const> samplers,
                  std::span<Color> out, RenderCounters &counters) const override;
    nlohmann::json describe() const override;
    const PathOptions &options() const { return options_; }
    const ShadowRayTester &shadow_rays() const { return *shadow_; }
    ShadowRayTester &shadow_rays() { return *shadow_; }

private:
    struct Candidate;  // one light sample of next event estimation
    struct Path;  // one path's state between stages
    // Stages of one bounce (see Li_batch). begin_vertex and finish_vertex return false when the path ends.
    bool begin_vertex(const Scene &scene, Path &path) const;
    // Next event estimation at the vertex: begin_light and sample_light sample the light chosen at
    // begin_vertex in two steps (Light::begin_sample, finish_sample), the second eight at a time where the
    // light allows it (LightSampleLanes: a rectangle of constant radiance); with resampling (ris > 1) that is
    // done for each candidate, weigh_candidates evaluates the BSDF toward each and prefetches its map
    // entry, and resample reads the entries and chooses one; begin_direct forms
    // the shadow query, its contribution MIS-weighted against BSDF sampling and multiplied by the path
    // throughput so contribution-aware policies see all of it (false: it contributes nothing); decide_direct asks the shadow-ray policy
    // and returns true when a ray must be traced, whose outcome end_direct takes.
    void begin_light(Path &path) const;
    void sample_light(Path &path, LightSampleLanes &lanes) const;
    void weigh_candidates(Path &path) const;
    void resample(Path &path) const;
    bool begin_direct(Path &path) const;
    bool decide_direct(Path &path, RenderCounters &counters) const;
    void end_direct(Path &path, bool occluded) const;
    // BSDF sampling and Russian roulette: the next ray, or false when the path ends.
    bool finish_vertex(Path &path) const;

    // MIS weight for emission found by a BSDF-sampled ray leaving prev (pdf prev_pdf) toward light.
    float emission_weight(const Light &light, const LightSampleContext &prev, const DirectionSample &ds,
                          float prev_pdf) const;
    bool resampling() const { return options_.ris > 1; }
    // The map's share of the resampling target, from the map the coming pass reads.
    void refresh_resampling();

    PathOptions options_;
    std::unique_ptr<ShadowRayTester> shadow_;
    const ShadowRayTester *queries_ = nullptr;  // shadow_->query_tester() for the coming pass
    std::unique_ptr<LightSampler> light_sampler_;
    WithinLightSampling within_light_;
    ResamplingVisibility resampling_visibility_;
};

}  // namespace neepp
