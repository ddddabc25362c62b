#include "neepp/visibility/neepp_shadow_rays.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <tuple>
#include "neepp/io/binary_io.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/map_file.h"

namespace neepp {

ShadowRayPolicy parse_shadow_ray_policy(const std::string &name) {
    if (name == "nee") return ShadowRayPolicy::TraceAll;
    if (name == "neepp") return ShadowRayPolicy::Neepp;
    if (name == "neepp-adaptive") return ShadowRayPolicy::NeeppAdaptive;
    if (name == "neepp-cv") return ShadowRayPolicy::NeeppCV;
    throw std::invalid_argument("unknown shadow-ray policy '" + name + "' (supported: nee, neepp, neepp-adaptive, neepp-cv)");
}

std::string to_string(ShadowRayPolicy policy) {
    switch (policy) {
        case ShadowRayPolicy::TraceAll: return "nee";
        case ShadowRayPolicy::Neepp: return "neepp";
        case ShadowRayPolicy::NeeppAdaptive: return "neepp-adaptive";
        case ShadowRayPolicy::NeeppCV: return "neepp-cv";
    }
    return "?";
}

NeeppShadowRays::NeeppShadowRays(NeeppOptions options)
    : options_(std::move(options)),
      ray_budget_(options_.policy == ShadowRayPolicy::NeeppAdaptive && options_.adaptive_target == "rays") {
    if (!(options_.q_min > 0.f && options_.q_min <= 1.f))
        throw std::invalid_argument("q_min must be in (0, 1]: q = 0 where visibility can be 1 would bias the image");
    if (options_.grid_bounds != "scene" && options_.grid_bounds != "shading")
        throw std::invalid_argument("grid_bounds must be 'scene' or 'shading'");
    if (options_.samples_per_pair < 1 || options_.samples_per_pair > 4096)
        throw std::invalid_argument("samples_per_pair must be in [1, 4096]");
    if (options_.voxels < 1 || options_.voxels > VoxelGrid::kMaxResolution)
        throw std::invalid_argument("voxels must be in [1, " + std::to_string(VoxelGrid::kMaxResolution) + "]");
}

float NeeppShadowRays::trace_probability(PairCounts c, bool same_cell, float lum) const {
    if (same_cell || c.traced == 0 || options_.policy == ShadowRayPolicy::TraceAll) return 1.f;
    const float v = VisibilityMap::estimate(c);
    if (options_.policy == ShadowRayPolicy::NeeppAdaptive && adaptive_scale_ > 0) {
        // NaN-safe: a NaN or negative luminance gives q_min, never 0.
        double x = adaptive_scale_ * double(std::max(lum, 0.f)) * std::sqrt(double(v));
        float q = float(std::min(x, 1.0));
        return q >= options_.q_min ? q : options_.q_min;
    }
    return std::min(1.f, std::max(v, options_.q_min));
}

// Shadow rays toward environment lights are spawned with an infinite tmax; they are keyed by direction.
std::pair<uint32_t, uint32_t> NeeppShadowRays::cells_of(const ShadowQuery &q) const {
    if (q.from_cell != ShadowQuery::kUnknownCell) return {q.from_cell, q.to_cell};
    const bool to_infinity = q.ray.tmax >= kInfinity;
    return {grid_.voxel_of(q.from), grid_.cell_of_end(q.to, q.ray.d, to_infinity)};
}

void NeeppShadowRays::prepare(ShadowQuery &q) const {
    if (phase_ == Phase::Off) return;  // begin_test will not look
    std::tie(q.from_cell, q.to_cell) = cells_of(q);
    if (options_.policy != ShadowRayPolicy::TraceAll && phase_ == Phase::Rejecting)
        map_.prefetch(VisibilityMap::pair_index(q.from_cell, q.to_cell));
}

const ShadowRayTester &NeeppShadowRays::query_tester() const {
    static const TraceAllShadowRays trace_all;  // stateless
    return phase_ == Phase::Off ? static_cast<const ShadowRayTester &>(trace_all) : *this;
}

ShadowTest NeeppShadowRays::begin_test(const ShadowQuery &q, Sampler &sampler, RenderCounters &counters) const {
    ShadowTest test;  // traced, weight V
    // With rejection off, plain NEE from here on: no lookup, no learning (the path integrator asks
    // query_tester() and does not come here then; other callers may).
    if (phase_ == Phase::Off) return test;
    const auto [a, b] = cells_of(q);
    const uint64_t pair = VisibilityMap::pair_index(a, b);
    ThreadState &ts = threads_.local();
    if (options_.learn) test.learn_pair = pair;
    if (options_.policy == ShadowRayPolicy::TraceAll) return test;  // learns, never reads the map
    if (phase_ == Phase::Probe && map_.pair_count() == 0) return test;  // seeding deferred: nothing to read
    const PairCounts c = map_.counts_at(pair);
    if (c.traced >= options_.learn_until) test.learn_pair = ShadowTest::kNoPair;
    if (phase_ == Phase::Probe) return test;  // the first pass traces every query
    if (a == b || c.traced == 0) {
        ++(a == b ? ts.forced_same_cell : ts.forced_unknown);
        return test;
    }

    const float v = VisibilityMap::estimate(c);
    const float lum = luminance(q.unoccluded);
    const float prob = trace_probability(c, false, lum);
    // The ray-budget calibration's inputs; the default (efficiency) calibration needs none of them, and
    // the log2 below costs a few percent of a cheap scene's render time.
    if (ray_budget_) {
        ts.paper_q_sum_fixed += uint64_t(std::min(1.f, std::max(v, options_.q_min)) * kFixedOne);
        double x = double(std::max(lum, 0.f)) * std::sqrt(double(v));
        int bin = 0;
        if (x > 0 && std::isfinite(x))
            bin = std::clamp(int(std::floor((std::log2(x) - kHistMinLog2) * kHistBinsPerOctave)), 0, kHistBins - 1);
        if (ts.histogram.empty()) ts.histogram.assign(kHistBins, 0);
        ++ts.histogram[size_t(bin)];
    }
    ++ts.roulettes;
    ts.q_sum_fixed += uint64_t(prob * kFixedOne);
    if (prob >= 1.f) {  // no roulette, no random number
        ++ts.roulette_traced;
        return test;  // q = 1: every policy's weight reduces to V
    }
    const bool cv = options_.policy == ShadowRayPolicy::NeeppCV;
    float u;
    {  // on a stream of its own, so that taking a roulette or not shifts none of the path's numbers
        const StreamScope roulette(sampler, SampleStream::Roulette);
        u = sampler.next_1d();
    }
    if (u < prob) {
        ++ts.roulette_traced;
        test.if_visible = cv ? v + (1.f - v) / prob : 1.f / prob;
        test.if_occluded = cv ? v - v / prob : 0.f;
        return test;
    }
    ++ts.skipped;
    ++counters.shadow_rays_skipped;
    test.trace = false;
    test.if_skipped = cv ? v : 0.f;
    return test;
}

void NeeppShadowRays::end_test(const ShadowTest &test, bool occluded) const {
    if (phase_ == Phase::Off) return;
    ThreadState &ts = threads_.local();
    if (test.learn_pair != ShadowTest::kNoPair) ts.updates.record(test.learn_pair, !occluded);
    if (phase_ == Phase::Probe) {
        ++ts.probe_traced;
        ts.probe_occluded += occluded;
    }
}

void NeeppShadowRays::adopt_map(const VoxelGrid &grid, VisibilityMap map) {
    if (map.cell_count() != grid.cell_count()) throw std::invalid_argument("adopt_map: map and grid disagree");
    grid_ = grid;
    map_ = std::move(map);
    adopted_ = true;
    map_source_ = "adopted";
}

void NeeppShadowRays::prepare(const Scene &scene) {
    threads_.clear();
    totals_ = Totals{};
    adaptive_scale_ = 0;
    phase_ = Phase::Probe;
    if (adopted_) return;
    seeding_ = SeedingStats{};
    load_time_s_ = 0;
    grid_ = VoxelGrid(options_.grid_bounds == "shading" ? shading_bounds(scene, SeedingOptions{}) : scene.bounds(),
                      options_.voxels);
    const uint64_t fingerprint = scene_fingerprint(scene);
    if (!options_.map_file.empty() && std::filesystem::exists(options_.map_file)) {
        // A file that exists but is damaged or belongs to another scene or grid is refused (throws), not
        // silently overwritten: the user named it, and may have named the wrong one.
        auto t0 = std::chrono::steady_clock::now();
        map_ = load_visibility_map(options_.map_file, grid_, fingerprint);
        load_time_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        map_source_ = "loaded";
        return;
    }
    scene_ = &scene;
    map_ = VisibilityMap();
    map_source_ = "not built";
    if (!options_.defer_seeding || options_.policy == ShadowRayPolicy::TraceAll) seed_map(scene);
}

void NeeppShadowRays::seed_map(const Scene &scene) {
    map_ = VisibilityMap(grid_.cell_count());
    SeedingOptions so;
    so.samples_per_pair = options_.samples_per_pair;
    seeding_ = seed_visibility_map(scene, grid_, map_, so);
    map_source_ = "built";
    if (!options_.map_file.empty()) save_visibility_map(options_.map_file, grid_, map_, scene_fingerprint(scene));
}

void NeeppShadowRays::calibrate_adaptive(const std::vector<uint64_t> &histogram, uint64_t roulettes,
                                         uint64_t paper_q_sum_fixed) {
    if (roulettes == 0 || histogram.empty()) return;
    const double target = double(paper_q_sum_fixed) / kFixedOne / double(roulettes);
    const double q_min = options_.q_min;
    auto mean_q = [&](double log2c) {
        double s = 0;
        for (int i = 0; i < kHistBins; ++i)
            if (histogram[size_t(i)]) {
                double x = std::exp2(log2c + kHistMinLog2 + (i + 0.5) / kHistBinsPerOctave);
                s += double(histogram[size_t(i)]) * std::clamp(x, q_min, 1.0);
            }
        return s / double(roulettes);
    };
    // mean_q is nondecreasing in c; bisect log2 c so the adaptive rule spends the paper's ray budget.
    double lo = -200, hi = 200;
    for (int it = 0; it < 80; ++it) {
        double mid = 0.5 * (lo + hi);
        (mean_q(mid) < target ? lo : hi) = mid;
    }
    adaptive_scale_ = std::exp2(0.5 * (lo + hi));
}

void NeeppShadowRays::end_pass(const PassStatistics &pass) {
    auto t0 = std::chrono::steady_clock::now();
    // Sum every thread's updates per pair first (exact integer sums: independent of how tiles were spread
    // over threads and of the order below), then apply each pair's sum once.
    PairUpdateBuffer merged;
    size_t entries = 0;
    for (const ThreadState &ts : threads_) entries += ts.updates.size();
    merged.reserve(entries);
    std::vector<uint64_t> histogram;
    uint64_t roulettes = 0, paper_q = 0;
    for (ThreadState &ts : threads_) {
        ts.updates.for_each([&](uint64_t pair, uint32_t v, uint32_t t) { merged.add(pair, v, t); });
        ts.updates.clear();
        totals_.roulettes += ts.roulettes;
        totals_.roulette_traced += ts.roulette_traced;
        totals_.skipped += ts.skipped;
        totals_.forced_unknown += ts.forced_unknown;
        totals_.forced_same_cell += ts.forced_same_cell;
        totals_.q_sum_fixed += ts.q_sum_fixed;
        roulettes += ts.roulettes;
        paper_q += ts.paper_q_sum_fixed;
        if (!ts.histogram.empty()) {
            if (histogram.empty()) histogram.assign(kHistBins, 0);
            for (int i = 0; i < kHistBins; ++i) histogram[size_t(i)] += ts.histogram[size_t(i)];
            std::fill(ts.histogram.begin(), ts.histogram.end(), 0);
        }
        ts.roulettes = ts.roulette_traced = ts.skipped = ts.forced_unknown = ts.forced_same_cell = 0;
        ts.q_sum_fixed = ts.paper_q_sum_fixed = 0;
        totals_.probe_traced += ts.probe_traced;
        totals_.probe_occluded += ts.probe_occluded;
        ts.probe_traced = ts.probe_occluded = 0;
    }
    if (phase_ == Phase::Probe && options_.policy != ShadowRayPolicy::TraceAll) {
        phase_ = occluded_fraction() >= double(options_.min_occluded) ? Phase::Rejecting : Phase::Off;
        if (phase_ == Phase::Rejecting && map_.pair_count() == 0) seed_map(*scene_);  // deferred seeding
    }
    // Pairs at learn_until take nothing more; begin_test already left them out, except in a first pass
    // whose map was only seeded after it.
    const bool capped = options_.policy != ShadowRayPolicy::TraceAll;
    if (map_.pair_count() != 0)  // else rejection is off and the map was never built: nothing to learn
        merged.for_each([&](uint64_t pair, uint32_t v, uint32_t t) {
            if (capped && map_.counts_at(pair).traced >= options_.learn_until) return;
            map_.add(pair, v, t);
            totals_.updates_merged += t;
        });
    if (options_.policy == ShadowRayPolicy::NeeppAdaptive) {
        if (options_.adaptive_target == "rays") calibrate_adaptive(histogram, roulettes, paper_q);
        else if (pass.sample_variance > 0)
            adaptive_scale_ = 1.0 / std::sqrt(double(options_.shadow_ray_cost) * pass.sample_variance);
    }
    ++totals_.passes;
    totals_.merge_time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

namespace {

// A saved state's parts: the learning's phase and calibration, its totals, and the map's file bytes.
template <typename Totals> struct SavedState {
    uint8_t phase = 0;
    double adaptive_scale = 0;
    Totals totals;
    SeedingStats seeding;
    std::string map_source;
    bool has_map = false;
    std::string map_bytes;

    std::string encode() const {
        BinaryWriter w;
        w.put(phase);
        w.put(adaptive_scale);
        w.put(totals);
        w.put(seeding);
        w.put_string(map_source);
        w.put(uint8_t(has_map));
        if (has_map) w.put_string(map_bytes);
        return std::move(w.bytes);
    }
    static SavedState decode(const std::string &bytes) {
        BinaryReader r{bytes, 0, "checkpoint: NEE++ state"};
        SavedState s;
        s.phase = r.get<uint8_t>();
        s.adaptive_scale = r.get<double>();
        s.totals = r.get<Totals>();
        s.seeding = r.get<SeedingStats>();
        s.map_source = r.get_string();
        s.has_map = r.get<uint8_t>() != 0;
        if (s.has_map) s.map_bytes = r.get_string();
        return s;
    }
};

}  // namespace

std::string NeeppShadowRays::save_state() const {
    SavedState<Totals> s{uint8_t(phase_), adaptive_scale_, totals_, seeding_, map_source_, map_.cell_count() != 0, {}};
    if (s.has_map) s.map_bytes = encode_visibility_map(grid_, map_, 0);
    return s.encode();
}

void NeeppShadowRays::restore_state(const std::string &state) {
    const auto s = SavedState<Totals>::decode(state);
    if (s.phase > uint8_t(Phase::Off)) throw std::runtime_error("checkpoint: NEE++ state: bad phase");
    phase_ = Phase(s.phase);
    adaptive_scale_ = s.adaptive_scale;
    totals_ = s.totals;
    seeding_ = s.seeding;
    map_source_ = s.map_source;
    map_ = s.has_map ? decode_visibility_map(s.map_bytes, "checkpoint: NEE++ map", grid_, 0) : VisibilityMap();
}

std::string NeeppShadowRays::merge_states(const std::string &base, const std::vector<std::string> &learned) const {
    if (learned.empty()) return base;
    auto merged = SavedState<Totals>::decode(learned.front());
    if (!merged.has_map || learned.size() == 1) return learned.front();
    const char *what = "merging NEE++ states";
    auto [grid, map] = decode_visibility_map(merged.map_bytes, what, 0);
    // What each other render added to the base map (a base without a map: all it holds). Learning stops
    // at learn_until (far below the counts' halving at 65535), so these differences are what it traced.
    VisibilityMap base_map;
    if (!base.empty()) {
        const auto b = SavedState<Totals>::decode(base);
        if (b.has_map) base_map = decode_visibility_map(b.map_bytes, what, grid, 0);
    }
    for (size_t i = 1; i < learned.size(); ++i) {
        const auto other = SavedState<Totals>::decode(learned[i]);
        if (!other.has_map) continue;
        const VisibilityMap theirs = decode_visibility_map(other.map_bytes, what, grid, 0);
        for (uint64_t pair = 0; pair < theirs.pair_count(); ++pair) {
            const PairCounts c = theirs.counts_at(pair);
            if (c.traced == 0) continue;
            const PairCounts b = base_map.pair_count() ? base_map.counts_at(pair) : PairCounts{};
            const int traced = int(c.traced) - int(b.traced);
            const int visible = std::clamp(int(c.visible) - int(b.visible), 0, std::max(traced, 0));
            if (traced > 0) map.add(pair, uint64_t(visible), uint64_t(traced));
        }
    }
    merged.map_bytes = encode_visibility_map(grid, map, 0);
    return merged.encode();
}

nlohmann::json NeeppShadowRays::describe() const {
    nlohmann::json j = {{"policy", policy()},
                        {"voxels", options_.voxels},
                        {"samples_per_pair", options_.samples_per_pair},
                        {"grid_bounds", options_.grid_bounds},
                        {"q_min", options_.q_min},
                        {"learn", options_.learn},
                        {"learn_until", options_.learn_until},
                        {"min_occluded", options_.min_occluded},
                        {"visibility_map", options_.map_file}};
    if (options_.policy == ShadowRayPolicy::NeeppAdaptive) {
        j["adaptive_target"] = options_.adaptive_target;
        j["shadow_ray_cost"] = options_.shadow_ray_cost;
    }
    return j;
}

nlohmann::json NeeppShadowRays::statistics() const {
    nlohmann::json map = {
        {"source", map_source_},
        {"file", options_.map_file},
        {"resolution", grid_.resolution()},
        {"cells", grid_.cell_count()},
        {"direction_bins", VoxelGrid::kDirectionBins},
        {"memory_mb", double(map_.memory_bytes()) / (1024.0 * 1024.0)},
        {"known_pairs", map_.cell_count() ? map_.known_pairs() : 0},
        {"build_time_s", seeding_.time_s},
        {"build_camera_rays", seeding_.camera_rays},
        {"build_shadow_rays", seeding_.shadow_rays},
        {"occupied_voxels", seeding_.occupied_voxels},
        {"light_cells", seeding_.light_cells},
        {"seeded_pairs", seeding_.seeded_pairs},
        {"load_time_s", load_time_s_},
    };
    const uint64_t decided = totals_.roulettes + totals_.forced_unknown + totals_.forced_same_cell;
    nlohmann::json roulette = {
        {"queries", decided},
        {"roulettes", totals_.roulettes},
        {"roulette_traced", totals_.roulette_traced},
        {"skipped", totals_.skipped},
        {"traced_unknown_pair", totals_.forced_unknown},
        {"traced_same_cell", totals_.forced_same_cell},
        {"mean_q", totals_.roulettes ? double(totals_.q_sum_fixed) / kFixedOne / double(totals_.roulettes) : 1.0},
        {"online_updates_merged", totals_.updates_merged},
        {"passes_merged", totals_.passes},
        {"merge_time_s", totals_.merge_time_s},
    };
    nlohmann::json j = {{"policy", policy()}, {"map", map}, {"roulette", roulette}};
    if (options_.policy != ShadowRayPolicy::TraceAll)
        j["rejection"] = {{"first_pass_shadow_rays", totals_.probe_traced},
                          {"first_pass_occluded_fraction", occluded_fraction()},
                          {"min_occluded", options_.min_occluded},
                          {"state", phase_ == Phase::Probe ? "first pass" : phase_ == Phase::Rejecting ? "on" : "off"}};
    if (options_.policy == ShadowRayPolicy::NeeppAdaptive) j["adaptive_scale"] = adaptive_scale_;
    return j;
}

}  // namespace neepp
