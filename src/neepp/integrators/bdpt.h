// Bidirectional path tracing (Veach & Guibas 1995; Veach's thesis ch. 10) and light tracing, with the
// path integrator's Mitsuba semantics for max_depth (edges of the whole path: 1 = emitters seen
// directly), rr_depth and hide_emitters. Every connection's shadow ray goes through the shadow-ray
// component, so NEE++'s policies apply to BDPT as they do to NEE.
//
// A camera subpath x0..x(t-1) and a light subpath y0..y(s-1) are joined by every strategy (s, t): s = 0
// is the camera path finding an emitter, s = 1 a light point sampled from x(t-1) (next event
// estimation), t = 1 a light-path vertex connected to the camera and splatted onto the film, the rest a
// connection between y(s-1) and x(t-1). The strategies are combined by MIS (power or balance heuristic)
// from the densities each vertex keeps (path_vertex.h).
//
// NEE++ light-subpath selection (shared/design/NEEPP.md §4, light_paths=neepp): before each pass a pool
// of M light subpaths is traced (their t = 1 strategies are splatted too: the film's splats are scaled by
// pixels / light paths). Each camera sample still traces its own light subpath, which alone serves the
// t = 1 and s <= 1 strategies, as in plain BDPT; its s >= 2, t >= 2 connections go to one of K candidates,
// its own light subpath and K - 1 drawn uniformly from the pool, scored by the visibility map between
// its vertices' voxels and the candidate's (times both throughputs' luminance), chosen with probability
// p_i ∝ score mixed with 10 % uniform, and weighted by 1 / (K p_i). The candidates are independent light
// subpaths, so this estimates what the connection with one light subpath does and every strategy keeps
// its MIS weight. K = 1 is plain BDPT. (Connecting only pool paths, shared among all camera samples, and
// leaving t = 1 to them gives many times plain BDPT's variance.)
#pragma once
#include <memory>
#include <string>
#include <vector>
#include "neepp/base/integrator.h"
#include "neepp/integrators/path_vertex.h"
#include "neepp/light_selection/within_light_sampling.h"
#include "neepp/visibility/shadow_ray_tester.h"

namespace neepp {

struct BDPTOptions {
    int max_depth = -1;
    int rr_depth = 5;
    bool hide_emitters = false;
    // `light` (particle tracing): light paths only, every vertex connected to the camera, unweighted.
    bool light_tracer = false;
    int strategy_s = -1, strategy_t = -1;  // one (s, t) strategy only (both >= 0), else all
    bool strategy_mis = true;              // that strategy MIS-weighted (as in the full image) or not
    bool power_heuristic = true;           // mis=power, else balance
    bool neepp_selection = false;          // light_paths=neepp
    int candidates = 8;                    // K
    int pool = 4096;                       // M
    int voxels = 16;
    // How the s = 1 strategies sample a point on the light they chose: area or solid-angle
    // (light_selection/solid_angle_sampling.h).
    std::string area_light_sampling = "area";
};

class BDPTIntegrator final : public SplattingIntegrator {
public:
    BDPTIntegrator(BDPTOptions options, std::unique_ptr<ShadowRayTester> shadow);
    void prepare(const Scene &scene) override;
    Color Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters,
             SplatSink &splats) const override;
    uint64_t begin_pass(const Scene &scene, const PassInfo &pass, SplatFilm &splats, RenderCounters &counters) override;
    void end_pass(const Scene &scene, const PassStatistics &pass) override;
    bool learns_between_passes() const override { return shadow_->learns_between_passes(); }
    // What the shadow-ray component has learned (NEE++'s map, phase, calibration).
    std::string save_state() const override { return shadow_->save_state(); }
    std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const override {
        return shadow_->merge_states(base, learned);
    }
    void restore_state(const Scene &scene, const std::string &state) override;
    nlohmann::json describe() const override;
    nlohmann::json statistics() const override;
    const BDPTOptions &options() const { return options_; }

    // The densities a strategy would have produced its path with, combined: the MIS weight of strategy
    // (s, t) for the path light[0..s) + camera[0..t) reversed, `sampled` standing in for light[0] (s = 1)
    // or camera[0] (t = 1). Public for tests (the weights of a path's strategies sum to one).
    float mis_weight(const std::vector<PathVertex> &light, const std::vector<PathVertex> &camera,
                     const PathVertex &sampled, int s, int t) const;
    const BidirContext &context() const { return ctx_; }
    ShadowRayTester &shadow_rays() { return *shadow_; }
    // The light choice of its s = 1 strategies (null before prepare()), for tools that show its distribution.
    const LightSampler *light_sampler() const { return light_sampler_.get(); }

private:
    // Light tracing's only camera-side term: the infinite lights the camera ray sees directly.
    Color visible_environment(const Scene &scene, const Ray &ray, RenderCounters &counters) const;
    // Contribution of strategy (s, t), MIS weight and visibility included; raster receives where a t = 1
    // strategy lands on the film.
    Color connect(const std::vector<PathVertex> &light, const std::vector<PathVertex> &camera, int s, int t,
                  Sampler &sampler, RenderCounters &counters, Vec2 &raster) const;
    bool wants(int s, int t) const;  // whether this render uses strategy (s, t)
    // Splats the t = 1 strategies of a light subpath (scaled by `scale`).
    void splat_light_path(const std::vector<PathVertex> &light, Sampler &sampler, RenderCounters &counters,
                          SplatSink &splats, float scale) const;
    // NEE++: the light subpath the camera subpath's s >= 2 connections use, among its own and K - 1 from
    // the pool, and its weight 1 / (K p).
    const std::vector<PathVertex> &choose_light_path(const std::vector<PathVertex> &camera,
                                                     const std::vector<PathVertex> &own, Sampler &sampler,
                                                     float &weight) const;

    BDPTOptions options_;
    WalkOptions camera_walk_, light_walk_;
    std::unique_ptr<ShadowRayTester> shadow_;
    const ShadowRayTester *queries_ = nullptr;
    std::unique_ptr<LightSampler> light_sampler_;
    // How s = 1 samples a point of the light it chose (null for a light: by its own sampling).
    WithinLightSampling area_lights_;
    BidirContext ctx_;
    // NEE++ pool of the coming pass: light subpaths and their vertices' voxels.
    std::vector<std::vector<PathVertex>> pool_;
    std::vector<std::vector<uint32_t>> pool_cells_;
    uint64_t pool_paths_traced_ = 0;
};

}  // namespace neepp
