// NEE++'s shadow-ray policies (Guo et al. 2020, see shared/design/NEEPP.md §1-2): a shadow ray from a
// shading point in cell a toward a light point in cell b is traced only with probability q, chosen from
// the visibility map's estimate Ṽ(a, b), and the result is reweighted so that E[weight] = V exactly.
//   neepp           the paper: q = max(Ṽ, q_min); weight V/q when traced, 0 when skipped.
//   neepp-adaptive  contribution-aware: q = clamp(c·lum(f)·sqrt(Ṽ), q_min, 1), which minimizes variance ×
//                   shadow-ray cost (Σ f²Ṽ/q subject to Σ q fixed gives q ∝ f·sqrt(Ṽ)). The scale c is
//                   calibrated after each pass so the expected number of rays traced equals what the
//                   paper's rule would trace on that pass's queries (same cost, variance moved to dim
//                   samples); the first pass, before any calibration, uses the paper's rule.
//   neepp-cv        control variate: q = max(Ṽ, q_min); weight Ṽ when skipped, Ṽ + (V − Ṽ)/q when traced.
//                   Same cost as neepp; per unit f², variance ν(1−ν)/q + (ν−Ṽ)²(1/q−1) for true visibility
//                   probability ν (paper's rule: ν/q − ν²), i.e. 1−ν instead of 1−ν² when Ṽ = ν. The weight
//                   is negative for a traced, occluded ray: any unbiased control variate needs that, so
//                   the film must keep negative samples.
// In every policy, the first pass (1 spp) traces every shadow ray, as NEE does: the map learns from the
// render's own queries, and the pass measures the fraction of shadow rays that are occluded. That
// fraction bounds what any rejection can save (only occluded rays are worth skipping); below min_occluded
// the policy stops rejecting for the rest of the render (the paper's stated limitation: scenes with simple
// visibility have little to gain, and a lookup per query plus the roulette's variance would cost more).
// With defer_seeding the map is seeded only once that decision is made (the first pass learns into
// per-thread buffers, merged into the seeded map). The decision reads counts, not timings, so renders
// stay reproducible; every pass is unbiased whichever way it went, since it is taken before the pass it
// applies to.
// In every policy, pairs the map has never seen and same-voxel pairs (whose visibility the map cannot
// resolve) are always traced, and q >= q_min > 0, so no sample with V = 1 is ever given zero probability.
// Every traced ray also updates its pair's counts: per-thread buffers during a pass, merged by
// end_pass() into the map that the next pass reads frozen.
#pragma once
#include <memory>
#include <string>
#include <utility>
#include <tbb/enumerable_thread_specific.h>
#include "neepp/visibility/map_seeding.h"
#include "neepp/visibility/shadow_ray_tester.h"
#include "neepp/visibility/update_buffer.h"
#include "neepp/visibility/visibility_map.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

// TraceAll ("nee") traces every shadow ray like TraceAllShadowRays but keeps (and learns) the map, for
// visibility-aware light selection without rejection.
enum class ShadowRayPolicy { TraceAll, Neepp, NeeppAdaptive, NeeppCV };
// "nee", "neepp", "neepp-adaptive", "neepp-cv"; throws std::invalid_argument otherwise.
ShadowRayPolicy parse_shadow_ray_policy(const std::string &name);
std::string to_string(ShadowRayPolicy policy);

struct NeeppOptions {
    ShadowRayPolicy policy = ShadowRayPolicy::Neepp;
    int voxels = 16;             // grid resolution N (the paper: higher is no better)
    int samples_per_pair = 16;   // explicit samples per pair when seeding (the paper: 16 suffice)
    // What the grid covers: "scene" (the scene's bounds) or "shading" (shading_bounds: where the camera's
    // paths shade, which differs where a scene holds large geometry far from what the camera sees).
    std::string grid_bounds = "scene";
    // Lower bound of q. It bounds the weight 1/q and so the variance blow-up where the map is wrong
    // (a pair estimated occluded that is in fact visible costs at most a factor 1/q_min in variance). 0.05
    // is the low end of the range NEEPP.md names: with the default 16 seeding samples, a pair seen fully
    // occluded has Ṽ = 1/18 ≈ 0.056, so q_min = 0.05 leaves the paper's rule untouched on the pairs that
    // matter and only catches estimates pushed lower by online learning.
    float q_min = 0.05f;
    // How the adaptive policy scales q = c·lum(f)·sqrt(Ṽ). "efficiency": c = 1 / sqrt(shadow_ray_cost ·
    // Var), which minimizes (time × variance) per sample: with T the time of a sample, c_r that of a
    // shadow ray and Var the variance of a pixel sample, d/dq_i [(T + c_r Σq)(Var + Σ f²ν(1/q − 1))] = 0
    // gives q_i = f_i·sqrt(ν_i)·sqrt(T / (c_r·Var)). Where shadow rays are cheap next to the rest of a
    // path, q approaches 1 and the policy falls back to plain NEE instead of losing to it.
    // "rays": c such that as many rays are traced as the paper's rule would (equal ray budget).
    std::string adaptive_target = "efficiency";
    // c_r / T: the time of one shadow ray as a fraction of a whole sample's. The default is what `nee`
    // takes on the Bitterli scenes (occlusion_time_s / shadow rays against render time per sample).
    // A fixed option, not a live timing, so renders stay reproducible.
    float shadow_ray_cost = 0.05f;
    std::string map_file;        // load if present and matching, else build and save here; "" = no file
    bool learn = true;           // update the map online from the shadow rays the render traces
    // ... until a pair's count reaches this: its Ṽ is then known to ±3 % (binomial standard error at most
    // 0.5/sqrt(n)), enough for choosing q, and each further update would be a hash-table write per shadow
    // ray that changes little. A map seeded wrong (16 samples) still learns 240 outcomes per pair before
    // it stops. Read from the frozen map, so renders stay reproducible; applies where the policy reads the
    // pair's counts anyway (roulette policies).
    int learn_until = 256;
    // Rejection stays on only if at least this fraction of the first pass's shadow rays were occluded
    // (0 = always on). Only occluded rays are worth skipping, and they are the cheap ones (an occlusion
    // query stops at the first hit, a visible ray crosses the whole scene): where fewer than half are
    // occluded, skipping them leaves Embree's time nearly unchanged while the lookups and the roulette's
    // variance cost every policy more than that saves.
    float min_occluded = 0.5f;
    // Build the map only after the first pass, and only if rejection stays on: a scene where rejection
    // does not pay then costs no seeding. The factory turns this off when a light sampler reads the map
    // from the first pass.
    bool defer_seeding = false;
};

class NeeppShadowRays final : public ShadowRayTester {
public:
    explicit NeeppShadowRays(NeeppOptions options);
    ShadowTest begin_test(const ShadowQuery &q, Sampler &sampler, RenderCounters &counters) const override;
    void end_test(const ShadowTest &test, bool occluded) const override;
    void prepare(ShadowQuery &q) const override;
    std::string policy() const override { return to_string(options_.policy); }
    // The adaptive policy's trace probability (and its ray-budget calibration) reads it.
    bool reads_contribution() const override { return options_.policy == ShadowRayPolicy::NeeppAdaptive; }
    void prepare(const Scene &scene) override;
    void end_pass(const PassStatistics &pass) override;
    // The phase, the adaptive calibration, the totals and the map (its known pairs).
    std::string save_state() const override;
    void restore_state(const std::string &state) override;
    // The first render's state, with the counts every other render added to the base map (counts add).
    std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const override;
    nlohmann::json describe() const override;
    nlohmann::json statistics() const override;

    // Probability of tracing a query whose pair has counts c, for a contribution of luminance lum; 1 for
    // unknown and same-cell pairs. Exposed so tests can check q > 0 over all inputs.
    float trace_probability(PairCounts c, bool same_cell, float lum) const;
    // Adaptive policy's current scale c (0 = not calibrated yet: the paper's rule is used).
    double adaptive_scale() const { return adaptive_scale_; }
    void set_adaptive_scale(double c) { adaptive_scale_ = c; }
    // Occluded fraction of the first pass's shadow rays (1 before any: no reason yet to turn off).
    double occluded_fraction() const {
        return totals_.probe_traced ? double(totals_.probe_occluded) / double(totals_.probe_traced) : 1.0;
    }

    // With rejection off (after the first pass), plain NEE: the same answers (trace all, learn nothing).
    const ShadowRayTester &query_tester() const override;
    bool learns_between_passes() const override { return phase_ != Phase::Off; }
    const VoxelGrid *voxel_grid() const override { return &grid_; }
    const VisibilityMap *visibility_map() const override { return &map_; }
    const NeeppOptions &options() const { return options_; }
    const VoxelGrid &grid() const { return grid_; }
    const VisibilityMap &map() const { return map_; }
    // For tests and tools (e.g. to plant a deliberately wrong map); not to be used during a pass.
    VisibilityMap &mutable_map() { return map_; }
    // Uses this grid and map instead of building one in prepare() (prepare then only resets the
    // per-render state). The grid must cover the scene that will be rendered.
    void adopt_map(const VoxelGrid &grid, VisibilityMap map);

private:
    // log2 histogram of lum(f)·sqrt(Ṽ) for the adaptive policy's calibration: integer counts, so the
    // merged histogram (and c) does not depend on how tiles were spread over threads.
    static constexpr int kHistBinsPerOctave = 4, kHistMinLog2 = -48, kHistBins = 96 * kHistBinsPerOctave;
    static constexpr double kFixedOne = double(1 << 24);  // fixed-point scale of summed probabilities
    struct ThreadState {
        PairUpdateBuffer updates;
        uint64_t roulettes = 0, roulette_traced = 0, skipped = 0, forced_unknown = 0, forced_same_cell = 0;
        uint64_t q_sum_fixed = 0;          // Σ q over roulettes, fixed point
        uint64_t paper_q_sum_fixed = 0;    // Σ max(Ṽ, q_min) over roulettes (the adaptive policy's budget)
        std::vector<uint64_t> histogram;   // adaptive only
        uint64_t probe_traced = 0, probe_occluded = 0;  // first pass
    };
    struct Totals {
        uint64_t roulettes = 0, roulette_traced = 0, skipped = 0, forced_unknown = 0, forced_same_cell = 0;
        uint64_t q_sum_fixed = 0, updates_merged = 0, passes = 0;
        double merge_time_s = 0;
        uint64_t probe_traced = 0, probe_occluded = 0;
    };
    // Probe: the first pass, tracing every ray. Then Rejecting, or Off (trace every ray, learn nothing).
    enum class Phase { Probe, Rejecting, Off };
    std::pair<uint32_t, uint32_t> cells_of(const ShadowQuery &q) const;  // (shading voxel, light cell)
    void calibrate_adaptive(const std::vector<uint64_t> &histogram, uint64_t roulettes, uint64_t paper_q_sum_fixed);

    NeeppOptions options_;
    bool ray_budget_;  // adaptive policy calibrated to the paper's ray budget (needs the histogram)
    VoxelGrid grid_;
    VisibilityMap map_;
    bool adopted_ = false;
    std::string map_source_;  // built, loaded, adopted; "not built" when deferred seeding was not needed
    const Scene *scene_ = nullptr;  // for deferred seeding
    void seed_map(const Scene &scene);
    SeedingStats seeding_;
    double load_time_s_ = 0;
    double adaptive_scale_ = 0;
    Phase phase_ = Phase::Probe;
    Totals totals_;
    // Native thread-local keys: local() is read on every shadow query, where the default hash lookup is a
    // visible cost.
    mutable tbb::enumerable_thread_specific<ThreadState, tbb::cache_aligned_allocator<ThreadState>, tbb::ets_key_per_instance>
        threads_;
};

}  // namespace neepp
