// NEE++'s visibility map: for every unordered pair of grid cells (a, b) the number of shadow rays traced
// between them and how many of those were unoccluded. Visibility is symmetric, so only one triangle is
// stored: pair (a, b) with a >= b lives at a(a+1)/2 + b. Counts (not a float) are kept so that the map
// can be updated online and its confidence judged; 2 × uint16 per pair keeps N = 16 (4192 cells with the
// direction bins, 8.79 M pairs) at 35 MB, the budget the paper's slides give.
#pragma once
#include <cstdint>
#include <vector>

namespace neepp {

struct PairCounts {
    uint16_t visible = 0;
    uint16_t traced = 0;
};
static_assert(sizeof(PairCounts) == 4);

class VisibilityMap {
public:
    static constexpr uint32_t kMaxCount = 65535;

    VisibilityMap() = default;
    explicit VisibilityMap(uint32_t cell_count);

    uint32_t cell_count() const { return cells_; }
    uint64_t pair_count() const { return counts_.size(); }
    static uint64_t pair_index(uint32_t a, uint32_t b) {
        if (a < b) std::swap(a, b);
        return uint64_t(a) * (uint64_t(a) + 1) / 2 + b;
    }

    PairCounts counts(uint32_t a, uint32_t b) const { return counts_[pair_index(a, b)]; }
    PairCounts counts_at(uint64_t pair) const { return counts_[pair]; }
    void prefetch(uint64_t pair) const { __builtin_prefetch(&counts_[pair]); }
    // Never traced: the policy must trace (and thereby learn) rather than guess.
    bool known(uint32_t a, uint32_t b) const { return counts(a, b).traced != 0; }
    // Ṽ = (visible + 1) / (traced + 2): a weak Beta(1,1) prior, so the estimate is never exactly 0 or 1
    // (an unseen outcome is never declared impossible). Unknown pairs give 0.5 here; callers check known().
    static float estimate(PairCounts c) { return (float(c.visible) + 1.f) / (float(c.traced) + 2.f); }
    float estimate(uint32_t a, uint32_t b) const { return estimate(counts(a, b)); }
    // Ṽ(a, b) where the map can tell, else 1: a pair never traced, and a cell with itself (whose
    // visibility the map cannot resolve), count as visible. What the map's readers weigh by.
    float estimate_or_visible(uint32_t a, uint32_t b) const {
        const PairCounts c = counts(a, b);
        return c.traced == 0 || a == b ? 1.f : estimate(c);
    }

    // Adds outcomes to a pair. When traced would exceed 65535 both counts are halved (repeatedly) so the
    // ratio survives and old evidence slowly fades. The result depends only on the old counts and the
    // sums added, so merging per-thread updates in any order gives the same map.
    void add(uint64_t pair, uint64_t visible, uint64_t traced);
    void add(uint32_t a, uint32_t b, uint64_t visible, uint64_t traced) { add(pair_index(a, b), visible, traced); }
    void set(uint64_t pair, PairCounts c) { counts_[pair] = c; }
    void set(uint32_t a, uint32_t b, PairCounts c) { counts_[pair_index(a, b)] = c; }

    uint64_t known_pairs() const;
    uint64_t memory_bytes() const { return counts_.size() * sizeof(PairCounts); }
    const std::vector<PairCounts> &data() const { return counts_; }

private:
    uint32_t cells_ = 0;
    std::vector<PairCounts> counts_;
};

}  // namespace neepp
