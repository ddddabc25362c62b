// The one place that traces shadow rays. Every integrator asks it "is the light sample visible from the
// shading point, and with what weight?"; it counts the rays and their time, and is where NEE++'s
// shadow-ray policies (Russian-roulette rejection driven by the visibility map) plug in.
#pragma once
#include <string>
#include <nlohmann/json.hpp>
#include "neepp/base/interaction.h"
#include "neepp/base/pass_statistics.h"
#include "neepp/base/stats.h"

namespace neepp {

class Scene;
class Sampler;
class VoxelGrid;
class VisibilityMap;

// Everything a policy may use to decide whether to trace: the ray, both end points, and the unoccluded
// contribution the sample would add (for contribution-aware policies).
struct ShadowQuery {
    Ray ray;
    Vec3 from, to;
    Color unoccluded;  // contribution if visible (throughput × f × Le / pdf, MIS included)
    // Where a policy keeps what it worked out about the query in prepare() (NEE++: the voxel of each end
    // point), so begin_test need not work it out again.
    static constexpr uint32_t kUnknownCell = ~0u;
    uint32_t from_cell = kUnknownCell, to_cell = kUnknownCell;
};

// A policy's decision on one query, taken before any ray is traced: whether to trace, and the weight of
// each outcome. Splitting decision and outcome lets an integrator trace many queries' rays at once.
struct ShadowTest {
    bool trace = true;
    float if_visible = 1.f, if_occluded = 0.f;  // weights when traced
    float if_skipped = 0.f;                     // weight when not traced
    static constexpr uint64_t kNoPair = ~uint64_t(0);
    uint64_t learn_pair = kNoPair;              // NEE++: the map pair the traced ray's outcome updates
    float weight(bool occluded) const { return trace ? (occluded ? if_occluded : if_visible) : if_skipped; }
};

class ShadowRayTester {
public:
    virtual ~ShadowRayTester() = default;
    // A test in two steps: begin_test decides whether to trace (drawing the roulette's number, if any),
    // the caller traces q.ray if asked (trace_shadow_ray, or in a packet) and gives the outcome to
    // end_test, which learns from it; the weight by which the unoccluded contribution is multiplied is
    // then test.weight(occluded): 0 if occluded (or rejected), 1 if visible, 1/q for a ray traced with
    // probability q. It must be unbiased: E[weight] = V. A policy that plays Russian roulette draws its one
    // random number from sampler.next_1d(), and only when a roulette actually happens. Called
    // concurrently from the render threads. (visibility/shadow_ray_tester.h's test_visibility does all
    // of it for one query.)
    virtual ShadowTest begin_test(const ShadowQuery &q, Sampler &sampler, RenderCounters &counters) const = 0;
    virtual void end_test(const ShadowTest &test, bool occluded) const {}
    // For integrators that form many queries before deciding any: locates q (NEE++: its voxel pair, kept
    // in q) and prefetches what begin_test(q) will read (the pair's map entry). Optional: begin_test
    // gives the same answer without it.
    virtual void prepare(ShadowQuery &q) const {}
    // Whether begin_test reads q.unoccluded (a contribution-aware policy). Where it does not, an
    // integrator may leave the expensive part of the contribution (BDPT's MIS weight) out of the query and
    // work it out only where the test's weight is not zero.
    virtual bool reads_contribution() const { return true; }
    virtual std::string policy() const = 0;
    // Hooks of the render loop, both single-threaded: prepare() before the first pass (build or load the
    // visibility map), end_pass() after each pass (merge what the pass learned; the next pass reads the
    // merged map, frozen).
    virtual void prepare(const Scene &scene) {}
    virtual void end_pass(const PassStatistics &) {}
    // A render checkpoint's share: what end_pass has learned so far, as bytes, and its restoration right
    // after prepare(scene), so that a resumed render's passes read what the uninterrupted one's would.
    virtual std::string save_state() const { return {}; }
    virtual void restore_state(const std::string &state) {}
    // Distributed rendering: several renders continued from the state `base` and each learned something
    // (`learned`, in a fixed order); the state that holds what all of them learned.
    virtual std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const {
        return learned.empty() ? base : learned.front();
    }
    // The policy's effective options (for the integrator's description) and its figures (map size and
    // build cost, roulette decisions...) for the statistics file.
    virtual nlohmann::json describe() const { return {{"policy", policy()}}; }
    virtual nlohmann::json statistics() const { return nlohmann::json::object(); }
    // NEE++'s grid and visibility map, when this component keeps one (for visibility-aware light
    // selection); valid after prepare(), updated by end_pass().
    virtual const VoxelGrid *voxel_grid() const { return nullptr; }
    virtual const VisibilityMap *visibility_map() const { return nullptr; }
    // The tester that answers the coming pass's queries (prepare(q), begin_test, end_test): itself, or
    // one that answers them the same way at less cost. NEE++ whose rejection stays off hands them to plain
    // NEE, so such a render costs per query exactly what `nee` does. Read after prepare(scene) and after
    // each end_pass(); valid as long as this tester.
    virtual const ShadowRayTester &query_tester() const { return *this; }
    // Whether the coming pass reads or updates the map, so that what it learns changes the next pass: the
    // render loop then keeps passes small early on. False once NEE++ has turned its rejection off (its
    // queries go to plain NEE and the map stays as it is), so such a render gets the full passes, and the
    // packets of one pixel's rays, that `nee` gets. Read after prepare(scene) and after each end_pass().
    virtual bool learns_between_passes() const { return false; }
};

}  // namespace neepp
