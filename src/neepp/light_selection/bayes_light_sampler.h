// A learned light choice after Vévoda, Kondapaneni and Křivánek, "Bayesian online regression for adaptive
// direct illumination sampling" (SIGGRAPH 2018), built on our light BVH and our voxel grid:
// - cache records: one per (voxel, receiver orientation) of a regular grid (TableKeys, as the oriented
//   spatial sampler's), where the paper places records at shading points and finds the nearest;
// - a light cut: one cut of the light BVH for all records (its nodes split by power until there are
//   cut_size of them), where the paper chooses a cut per record by an error bound;
// - per record and cut node, what NEE's own samples through that node showed: how many there were, how
//   many contributed (the node's "visibility", with a Beta prior), and the log of the contributions that
//   did, each divided by the plain descent's probability below the node (so it estimates the node's whole
//   contribution). The log-contribution is a normal of unknown mean and variance with a normal-gamma
//   prior whose mean follows the BVH's own importance at the record (plus a share of the node's power),
//   so a record with few samples falls back to the BVH's choice;
// - the node is chosen in proportion to the posterior expected contribution E[V]·E[x] (the paper's) or
//   the root of its second moment √(E[V]·E[x²]) (variance-aware, as in later work), and the light below it
//   by the plain BVH descent at the shading point.
// p(l | x) = P_rec(node) · p_bvh(l | node, x) with P_rec = (1 − ε) · posterior + ε · prior: the prior's
// power share is > 0 for every node, so every light the BVH can reach below its node keeps a nonzero
// probability whatever was learned. One table lookup and the descent below the node per choice: with at
// most cut_size lights the cut is the leaves and there is no descent at all. Samples
// are reported during a pass (LightSelectionLearner::record, thread-safe, integer sums so the result does
// not depend on the threads' order) and change the tables only at end_pass: within a pass the pmf is
// fixed and exact. Infinite lights are chosen apart, as in the BVH.
#pragma once
#include <atomic>
#include <memory>
#include "neepp/base/light_selection_learner.h"
#include "neepp/light_selection/bvh_light_sampler.h"
#include "neepp/light_selection/lazy_voxel_array.h"
#include "neepp/light_selection/spatial_light_sampler.h"

namespace neepp {

struct BayesSelectionOptions {
    int cut_size = 64;             // cut nodes per record (fewer when the BVH has fewer lights)
    float epsilon = 0.1f;          // share of the prior in a record's node choice: the defensive floor
    bool second_moment = false;    // choose ∝ √E[(V·x)²] (variance-aware) rather than E[V·x]
    bool oriented = true;          // records per (voxel, receiver orientation) rather than per voxel
    // The prior, in pseudo-samples: kappa0 on the log-contribution's mean, gamma(alpha0, beta0) on its
    // precision (prior E[σ²] = beta0 / (alpha0 − 1)), Beta(a0, b0) on the share of samples that contribute.
    float kappa0 = 2.f, alpha0 = 2.f, beta0 = 1.f, a0 = 1.f, b0 = 1.f;
    float prior_power_share = 0.2f;  // of the prior's mean: node power, the rest the BVH importance
};

class BayesLightSampler final : public LightSampler, public LightSelectionLearner {
public:
    BayesLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid, BayesSelectionOptions options = {});
    ~BayesLightSampler() override;
    SampledLight sample(const LightSampleContext &ctx, float u) const override;
    float pmf(const LightSampleContext &ctx, const Light &light) const override;
    std::string name() const override { return options_.second_moment ? "bayes-va" : "bayes"; }
    void end_pass() override;
    nlohmann::json statistics() const override;
    LightSelectionLearner *learner() override { return this; }

    void record(const LightSampleContext &ctx, const Light &light, float estimate) const override;
    std::string save_state() const override;
    void restore_state(const std::string &state) override;
    std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const override {
        return merge_encoded(base, learned);
    }
    // The same without a sampler: the states carry their grid and cut sizes.
    static std::string merge_encoded(const std::string &base, const std::vector<std::string> &learned);

    // For tests: the cut's size, and the probability a record gives to cut node `slot` this pass.
    size_t cut_size() const { return cut_.size(); }
    float node_probability(const LightSampleContext &ctx, size_t slot) const;

private:
    struct CutNode {
        uint32_t node;
        int depth;
        uint64_t bits;  // the path from the root, as BVHLightSampler::Trail's
    };
    // What a record learned about one cut node, in integers: log-contributions in fixed point, so that
    // sums do not depend on the order the threads add them in.
    struct NodeStats {
        uint64_t samples = 0, contributing = 0;
        int64_t log_sum = 0, log_square_sum = 0;
    };
    struct PendingStats {
        std::atomic<uint64_t> samples{0}, contributing{0};
        std::atomic<int64_t> log_sum{0}, log_square_sum{0};
    };
    static constexpr double kLogScale = 256.0;  // fixed-point steps per unit of log-contribution
    using Learned = std::vector<std::vector<NodeStats>>;  // per record; empty: nothing learned

    // The pmf of a light in the tree, from the plain descent's probability below its cut node and the
    // record's probability of the node; sample() and pmf() both end here, so they agree to the bit.
    static float mix(float p_inf, float below, float node) { return (1 - p_inf) * below * node; }
    void build_cut();
    const float *table(uint32_t key) const;         // P_rec over the cut, then its running sum
    std::unique_ptr<float[]> build_table(uint32_t key) const;
    std::vector<double> prior(uint32_t key) const;  // the prior's node distribution at a record
    PendingStats *pending(uint32_t key) const;      // allocated on first use
    static std::string format(const Learned &learned, uint32_t keys, uint32_t cut);
    static Learned parse(const std::string &state, uint32_t &keys, uint32_t &cut);

    BayesSelectionOptions options_;
    BVHLightSampler bvh_;
    TableKeys keys_;
    std::vector<CutNode> cut_;
    std::vector<int32_t> slot_of_light_;  // by Light::index: its cut node's slot, or -1
    Learned learned_;                     // what the passes so far taught, frozen during a pass
    std::unique_ptr<std::atomic<PendingStats *>[]> pending_;  // what this pass reports, per record
    LazyVoxelArray<float[]> tables_;
    uint64_t samples_learned_ = 0;
    uint64_t passes_ = 0;
};

}  // namespace neepp
