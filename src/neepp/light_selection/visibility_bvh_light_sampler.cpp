#include "neepp/light_selection/visibility_bvh_light_sampler.h"

#include <stdexcept>

namespace neepp {

VisibilityBVHLightSampler::VisibilityBVHLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid,
                                                     const VisibilityMap &map, const Vec3 &reference, float epsilon,
                                                     float delta)
    : bvh_(lights), grid_(grid), visibility_(grid, map, lights, reference), epsilon_(epsilon), delta_(delta),
      factors_(grid.voxel_count()) {
    if (!(epsilon > 0 && epsilon <= 1))
        throw std::invalid_argument("the defensive fraction must be in (0, 1]: a light with zero probability would bias the image");
    if (!(delta > 0 && delta <= 1)) throw std::invalid_argument("delta must be in (0, 1]");
}

const float *VisibilityBVHLightSampler::factors(uint32_t voxel) const {
    return factors_.get(voxel, [this](uint32_t a) {
        // Bottom-up (children follow their parent in the node array): mean visibility of a subtree,
        // weighted by its lights' power, then floored by delta so no branch is ever closed.
        const size_t n = bvh_.node_count();
        std::vector<float> mean(n, 1.f);
        for (size_t k = n; k-- > 0;) {
            const uint32_t node = uint32_t(k);
            if (bvh_.is_leaf(node)) {
                mean[node] = visibility_(a, bvh_.leaf_light(node));
                continue;
            }
            const uint32_t c0 = node + 1, c1 = bvh_.second_child(node);
            const float p0 = bvh_.node_power(c0), p1 = bvh_.node_power(c1);
            mean[node] = p0 + p1 > 0 ? (p0 * mean[c0] + p1 * mean[c1]) / (p0 + p1) : 1.f;
        }
        auto f = std::make_unique<Factors>(n);
        for (size_t k = 0; k < n; ++k) (*f)[k] = std::max(mean[k], delta_);
        return f;
    })
        .data();
}

SampledLight VisibilityBVHLightSampler::sample(const LightSampleContext &ctx, float u) const {
    const float *f = factors(grid_.voxel_of(ctx.p));
    // One descent chooses the light; the pmf of the other strategy is recomputed along its path.
    SampledLight s;
    float p_plain, p_visible;
    if (u < epsilon_) {
        s = bvh_.sample_weighted(ctx, std::min(u / epsilon_, kOneMinusEpsilon), nullptr);
        if (!s.light) return {};
        p_plain = s.pmf;
        p_visible = bvh_.pmf_weighted(ctx, *s.light, f);
    } else {
        s = bvh_.sample_weighted(ctx, std::min((u - epsilon_) / (1 - epsilon_), kOneMinusEpsilon), f);
        if (!s.light) return {};
        p_visible = s.pmf;
        p_plain = bvh_.pmf_weighted(ctx, *s.light, nullptr);
    }
    return {s.light, mix(p_plain, p_visible)};
}

float VisibilityBVHLightSampler::pmf(const LightSampleContext &ctx, const Light &light) const {
    const float *f = factors(grid_.voxel_of(ctx.p));
    return mix(bvh_.pmf_weighted(ctx, light, nullptr), bvh_.pmf_weighted(ctx, light, f));
}

nlohmann::json VisibilityBVHLightSampler::statistics() const {
    nlohmann::json s = bvh_.statistics();
    s["epsilon"] = epsilon_;
    s["delta"] = delta_;
    s["light_cells"] = visibility_.covered_cells();
    s["tables_built"] = factors_.built();  // over all passes
    return s;
}

}  // namespace neepp
