#include "neepp/visibility/visibility_map.h"

#include <stdexcept>
#include <string>

namespace neepp {

VisibilityMap::VisibilityMap(uint32_t cell_count) : cells_(cell_count) {
    if (cell_count == 0) throw std::invalid_argument("visibility map: no cells");
    counts_.assign(uint64_t(cell_count) * (uint64_t(cell_count) + 1) / 2, PairCounts{});
}

void VisibilityMap::add(uint64_t pair, uint64_t visible, uint64_t traced) {
    PairCounts &c = counts_[pair];
    uint64_t v = c.visible + visible, t = c.traced + traced;
    // Floor-halving both keeps v <= t; repeated for huge merges.
    while (t > kMaxCount) {
        v >>= 1;
        t >>= 1;
    }
    c.visible = uint16_t(v);
    c.traced = uint16_t(t);
}

uint64_t VisibilityMap::known_pairs() const {
    uint64_t n = 0;
    for (const PairCounts &c : counts_) n += c.traced != 0;
    return n;
}

}  // namespace neepp
