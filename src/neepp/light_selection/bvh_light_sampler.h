// The light BVH of Conty Estevez & Kulla (2018), the state-of-the-art many-light baseline (as pbrt-v4's
// `bvh` light sampler): lights with finite extent sit in a binary tree whose nodes bound position,
// emission direction and power; a light is chosen by descending from the root, picking each child in
// proportion to its importance at the shading point (LightBounds::importance). Infinite lights are
// chosen apart, each with the probability of one BVH. The pmf of a light is the product of the branch
// probabilities along its path, recomputed exactly by following the path stored per light.
#pragma once
#include <cstdint>
#include <vector>
#include "neepp/base/light_sampler.h"

namespace neepp {

class BVHLightSampler final : public LightSampler {
public:
    explicit BVHLightSampler(std::vector<const Light *> lights);
    SampledLight sample(const LightSampleContext &ctx, float u) const override { return sample_weighted(ctx, u, nullptr); }
    // One descent for all: each node's importance is computed once for every sample that passes it.
    void sample_many(const LightSampleContext &ctx, const float *u, int n, SampledLight *out) const override;
    float pmf(const LightSampleContext &ctx, const Light &light) const override { return pmf_weighted(ctx, light, nullptr); }
    std::string name() const override { return "bvh"; }
    nlohmann::json statistics() const override;

    // The same descent with each node's importance multiplied by factor[node] (> 0; null: all 1), the
    // hook through which visibility reweights the tree (VisibilityBVHLightSampler). For a given factor
    // array the pmf sample_weighted reports is bit-identical to pmf_weighted's.
    SampledLight sample_weighted(const LightSampleContext &ctx, float u, const float *factor) const;
    float pmf_weighted(const LightSampleContext &ctx, const Light &light, const float *factor) const;

    // The tree, for building per-node factors: nodes in depth-first order (a node's first child follows
    // it, so children always come after their parent).
    size_t node_count() const { return nodes_.size(); }
    bool is_leaf(uint32_t node) const { return nodes_[node].leaf; }
    uint32_t second_child(uint32_t node) const { return nodes_[node].child_or_light; }
    const Light &leaf_light(uint32_t node) const { return *entries_[nodes_[node].child_or_light].light; }
    float node_power(uint32_t node) const { return nodes_[node].bounds.phi; }
    int depth() const { return depth_; }

    // For samplers that choose a subtree first and let the plain descent choose below it (the Bayesian
    // sampler's light cut). A light's path from the root: bit d set = second child at depth d.
    struct Trail {
        uint64_t bits = 0;
        int length = -1;  // -1: not in the tree (infinite, or without power)
        bool infinite = false;
    };
    Trail trail(const Light &light) const;
    // The probability the plain descent gives to choosing infinite lights (each: this / count), and those.
    float infinite_probability() const;
    const std::vector<const Light *> &infinite_lights() const { return infinite_; }
    // The plain descent from `node` (at depth `from`) along trail bits down to depth `to`: the product of
    // its branch probabilities at ctx (0 where neither child can light ctx, or where `to` is a leaf that
    // cannot), the node it ends at in *end. From the root to a light's leaf this is pmf() / (1 − p_inf).
    float descent_probability(uint32_t node, int from, int to, uint64_t bits, const LightSampleContext &ctx,
                              uint32_t *end = nullptr) const;
    // The plain descent from `node` down to a light, with the probability of that light given the node.
    SampledLight sample_below(uint32_t node, const LightSampleContext &ctx, float u) const;

private:
    struct Node {
        CompactLightBounds bounds;
        uint32_t child_or_light = 0;  // interior: second child (the first is the next node); leaf: light
        bool leaf = false;
    };
    // What the sampler knows of each light, by Light::index.
    struct Entry {
        const Light *light = nullptr;
        bool infinite = false;  // chosen apart from the tree
        uint64_t bits = 0;      // path from the root: bit d set = went to the second child at depth d
        int length = -1;        // path length; -1: not in the tree (infinite, or without power)
    };
    uint32_t build(std::vector<std::pair<const Light *, LightBounds>> &items, size_t begin, size_t end,
                   uint64_t bits, int depth);
    // Probability of descending from an interior node into its first child (-1: neither child can light
    // ctx). sample and pmf both call it, so their products agree to the bit.
    float first_child_probability(uint32_t node, const LightSampleContext &ctx, const float *factor) const;
    // sample_many's descent below node of n samples, each with its rescaled number and pmf so far.
    struct Descent {
        float u, pmf;
        int index;  // in sample_many's out
    };
    void descend(uint32_t node, Descent *walks, int n, const LightSampleContext &ctx, SampledLight *out) const;

    std::vector<const Light *> infinite_;
    std::vector<Node> nodes_;
    std::vector<Entry> entries_;  // by Light::index
    int depth_ = 0;
};

}  // namespace neepp
