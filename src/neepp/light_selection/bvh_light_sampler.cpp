#include "neepp/light_selection/bvh_light_sampler.h"

#include <algorithm>
#include <cmath>

namespace neepp {

namespace {

// Conty & Kulla's orientation measure: the solid angle (cosine-weighted beyond theta_o) into which a
// cone of normals with emission spread theta_e can send light.
float orientation_measure(const LightBounds &b) {
    const float theta_o = std::acos(std::clamp(b.normals.cos_theta, -1.f, 1.f));
    const float theta_e = std::acos(std::clamp(b.cos_theta_e, -1.f, 1.f));
    const float theta_w = std::min(theta_o + theta_e, kPi);
    const float sin_o = std::sin(theta_o), cos_o = std::cos(theta_o);
    return 2 * kPi * (1 - cos_o) +
           kPi / 2 * (2 * theta_w * sin_o - std::cos(theta_o - 2 * theta_w) - 2 * theta_o * sin_o + cos_o);
}

float surface_area(const BBox &b) {
    const Vec3 e = vmax(b.extent(), Vec3(0.f));
    return 2 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

}  // namespace

BVHLightSampler::BVHLightSampler(std::vector<const Light *> lights) {
    uint32_t max_index = 0;
    for (const Light *l : lights) max_index = std::max(max_index, l->index);
    entries_.assign(lights.empty() ? 0 : max_index + 1, Entry{});
    for (const Light *l : lights) entries_[l->index].light = l;
    std::vector<std::pair<const Light *, LightBounds>> items;
    for (const Light *l : lights) {
        std::optional<LightBounds> b = l->is_infinite() ? std::nullopt : l->bounds();
        if (!b) {  // infinite (or unbounded) lights are chosen apart
            infinite_.push_back(l);
            entries_[l->index].infinite = true;
        } else if (b->phi > 0) {  // a light without power can light nothing: leave it out
            items.emplace_back(l, *b);
        }
    }
    if (!items.empty()) build(items, 0, items.size(), 0, 0);
}

uint32_t BVHLightSampler::build(std::vector<std::pair<const Light *, LightBounds>> &items, size_t begin, size_t end,
                                uint64_t bits, int depth) {
    depth_ = std::max(depth_, depth);
    const uint32_t index = uint32_t(nodes_.size());
    if (end - begin == 1) {
        nodes_.push_back({CompactLightBounds(items[begin].second), items[begin].first->index, true});
        Entry &e = entries_[items[begin].first->index];
        e.bits = bits;
        e.length = depth;
        return index;
    }
    LightBounds all;
    BBox centroids;
    for (size_t i = begin; i < end; ++i) {
        all = bounds_union(all, items[i].second);
        centroids.expand(items[i].second.bounds.center());
    }

    // Surface-area-orientation heuristic over 12 buckets per axis; the trail is 64 bits, so deep trees
    // (only reachable with adversarial inputs) fall back to halving by count.
    size_t mid = begin + (end - begin) / 2;
    const Vec3 extent = all.bounds.extent();
    const float max_extent = max_component(extent);
    float best_cost = kInfinity;
    int best_axis = -1, best_bucket = -1;
    constexpr int kBuckets = 12;
    if (depth < 48) {
        for (int axis = 0; axis < 3; ++axis) {
            const float lo = centroids.lo[axis], hi = centroids.hi[axis];
            if (!(hi > lo)) continue;
            LightBounds buckets[kBuckets];
            for (size_t i = begin; i < end; ++i) {
                int b = std::min(int(kBuckets * (items[i].second.bounds.center()[axis] - lo) / (hi - lo)), kBuckets - 1);
                buckets[b] = bounds_union(buckets[b], items[i].second);
            }
            auto cost_of = [](const LightBounds &b) {
                return b.phi > 0 ? b.phi * orientation_measure(b) * surface_area(b.bounds) : 0.f;
            };
            // Regularizer: thin slabs cut along their long axis are preferred.
            const float kr = extent[axis] > 0 ? max_extent / extent[axis] : 1.f;
            for (int split = 1; split < kBuckets; ++split) {
                LightBounds below, above;
                for (int b = 0; b < split; ++b) below = bounds_union(below, buckets[b]);
                for (int b = split; b < kBuckets; ++b) above = bounds_union(above, buckets[b]);
                if (below.phi <= 0 || above.phi <= 0) continue;
                const float cost = kr * (cost_of(below) + cost_of(above));
                if (cost < best_cost) { best_cost = cost; best_axis = axis; best_bucket = split; }
            }
        }
    }
    if (best_axis >= 0) {
        const float lo = centroids.lo[best_axis], hi = centroids.hi[best_axis];
        auto it = std::partition(items.begin() + ptrdiff_t(begin), items.begin() + ptrdiff_t(end), [&](const auto &item) {
            int b = std::min(int(kBuckets * (item.second.bounds.center()[best_axis] - lo) / (hi - lo)), kBuckets - 1);
            return b < best_bucket;
        });
        mid = size_t(it - items.begin());
    }
    if (mid == begin || mid == end) mid = begin + (end - begin) / 2;

    nodes_.push_back({CompactLightBounds(all), 0, false});
    build(items, begin, mid, bits, depth + 1);
    const uint32_t second = build(items, mid, end, bits | (uint64_t(1) << depth), depth + 1);
    nodes_[index].child_or_light = second;
    return index;
}

float BVHLightSampler::infinite_probability() const {
    if (infinite_.empty()) return 0.f;
    return float(infinite_.size()) / float(infinite_.size() + (nodes_.empty() ? 0 : 1));
}

float BVHLightSampler::first_child_probability(uint32_t node, const LightSampleContext &ctx, const float *factor) const {
    const uint32_t first = node + 1, second = nodes_[node].child_or_light;
    float i0 = nodes_[first].bounds.importance(ctx.p, ctx.n);
    float i1 = nodes_[second].bounds.importance(ctx.p, ctx.n);
    if (factor) {
        i0 *= factor[first];
        i1 *= factor[second];
    }
    if (!(i0 > 0) && !(i1 > 0)) return -1.f;
    return i0 / (i0 + i1);
}

SampledLight BVHLightSampler::sample_weighted(const LightSampleContext &ctx, float u, const float *factor) const {
    const float p_inf = infinite_probability();
    if (u < p_inf) {
        u = std::min(u / p_inf, kOneMinusEpsilon);
        size_t i = std::min(size_t(u * float(infinite_.size())), infinite_.size() - 1);
        return {infinite_[i], p_inf / float(infinite_.size())};
    }
    if (nodes_.empty()) return {};
    u = std::min((u - p_inf) / (1 - p_inf), kOneMinusEpsilon);
    float pmf = 1 - p_inf;
    uint32_t node = 0;
    while (!nodes_[node].leaf) {
        const uint32_t first = node + 1, second = nodes_[node].child_or_light;
        const float p0 = first_child_probability(node, ctx, factor);
        if (p0 < 0) return {};
        if (u < p0) {
            u = std::min(u / p0, kOneMinusEpsilon);
            pmf *= p0;
            node = first;
        } else {
            u = std::min((u - p0) / (1 - p0), kOneMinusEpsilon);
            pmf *= 1 - p0;
            node = second;
        }
    }
    // A leaf reached through a sibling's importance may itself light nothing here.
    if (!(nodes_[node].bounds.importance(ctx.p, ctx.n) > 0)) return {};
    const uint32_t light = nodes_[node].child_or_light;
    return {entries_[light].light, pmf};
}

void BVHLightSampler::sample_many(const LightSampleContext &ctx, const float *u, int n, SampledLight *out) const {
    // The same operations on each sample's number as sample_weighted's, so the same result to the bit.
    constexpr int kChunk = 64;
    const float p_inf = infinite_probability();
    for (int base = 0; base < n; base += kChunk) {
        Descent walks[kChunk];
        int m = 0;
        for (int i = base; i < std::min(n, base + kChunk); ++i) {
            float ui = u[i];
            out[i] = {};
            if (ui < p_inf) {
                ui = std::min(ui / p_inf, kOneMinusEpsilon);
                size_t k = std::min(size_t(ui * float(infinite_.size())), infinite_.size() - 1);
                out[i] = {infinite_[k], p_inf / float(infinite_.size())};
            } else if (!nodes_.empty()) {
                walks[m++] = {std::min((ui - p_inf) / (1 - p_inf), kOneMinusEpsilon), 1 - p_inf, i};
            }
        }
        descend(0, walks, m, ctx, out);
    }
}

void BVHLightSampler::descend(uint32_t node, Descent *walks, int n, const LightSampleContext &ctx,
                              SampledLight *out) const {
    while (n > 0 && !nodes_[node].leaf) {
        const float p0 = first_child_probability(node, ctx, nullptr);
        if (p0 < 0) return;
        Descent *second = std::partition(walks, walks + n, [&](const Descent &w) { return w.u < p0; });
        for (Descent *w = walks; w != second; ++w) {
            w->u = std::min(w->u / p0, kOneMinusEpsilon);
            w->pmf *= p0;
        }
        for (Descent *w = second; w != walks + n; ++w) {
            w->u = std::min((w->u - p0) / (1 - p0), kOneMinusEpsilon);
            w->pmf *= 1 - p0;
        }
        descend(nodes_[node].child_or_light, second, int(walks + n - second), ctx, out);
        node = node + 1;
        n = int(second - walks);
    }
    if (n == 0 || !(nodes_[node].bounds.importance(ctx.p, ctx.n) > 0)) return;
    const Light *light = entries_[nodes_[node].child_or_light].light;
    for (int k = 0; k < n; ++k) out[walks[k].index] = {light, walks[k].pmf};
}

float BVHLightSampler::pmf_weighted(const LightSampleContext &ctx, const Light &light, const float *factor) const {
    if (light.index >= entries_.size()) return 0.f;
    const float p_inf = infinite_probability();
    const Entry &trail = entries_[light.index];
    if (trail.infinite) return p_inf / float(infinite_.size());
    if (trail.length < 0) return 0.f;
    float pmf = 1 - p_inf;
    uint32_t node = 0;
    for (int d = 0; d < trail.length; ++d) {
        const uint32_t first = node + 1, second = nodes_[node].child_or_light;
        const float p0 = first_child_probability(node, ctx, factor);
        if (p0 < 0) return 0.f;
        if ((trail.bits >> d) & 1) {
            pmf *= 1 - p0;
            node = second;
        } else {
            pmf *= p0;
            node = first;
        }
    }
    if (!(nodes_[node].bounds.importance(ctx.p, ctx.n) > 0)) return 0.f;
    return pmf;
}

BVHLightSampler::Trail BVHLightSampler::trail(const Light &light) const {
    if (light.index >= entries_.size() || entries_[light.index].light != &light) return {};
    const Entry &e = entries_[light.index];
    return {e.bits, e.length, e.infinite};
}

float BVHLightSampler::descent_probability(uint32_t node, int from, int to, uint64_t bits, const LightSampleContext &ctx,
                                           uint32_t *end) const {
    float p = 1.f;
    for (int d = from; d < to; ++d) {
        const float p0 = first_child_probability(node, ctx, nullptr);
        if (p0 < 0) return 0.f;
        if ((bits >> d) & 1) {
            p *= 1 - p0;
            node = nodes_[node].child_or_light;
        } else {
            p *= p0;
            node = node + 1;
        }
    }
    if (end) *end = node;
    if (nodes_[node].leaf && !(nodes_[node].bounds.importance(ctx.p, ctx.n) > 0)) return 0.f;
    return p;
}

SampledLight BVHLightSampler::sample_below(uint32_t node, const LightSampleContext &ctx, float u) const {
    float pmf = 1.f;
    while (!nodes_[node].leaf) {
        const float p0 = first_child_probability(node, ctx, nullptr);
        if (p0 < 0) return {};
        if (u < p0) {
            u = std::min(u / p0, kOneMinusEpsilon);
            pmf *= p0;
            node = node + 1;
        } else {
            u = std::min((u - p0) / (1 - p0), kOneMinusEpsilon);
            pmf *= 1 - p0;
            node = nodes_[node].child_or_light;
        }
    }
    if (!(nodes_[node].bounds.importance(ctx.p, ctx.n) > 0)) return {};
    return {entries_[nodes_[node].child_or_light].light, pmf};
}

nlohmann::json BVHLightSampler::statistics() const {
    return {{"nodes", nodes_.size()}, {"depth", depth_}, {"infinite_lights", infinite_.size()}};
}

}  // namespace neepp
