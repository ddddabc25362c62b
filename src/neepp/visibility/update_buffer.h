// A thread's record of the shadow rays it traced during one pass, summed per voxel pair: a small
// open-addressing hash table (pair -> visible, traced). A render pass can trace tens of millions of
// shadow rays but touches far fewer distinct pairs, so summing in place keeps memory bounded; sums are
// order-independent, which is what makes the merged map (and so the next pass) reproducible.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace neepp {

class PairUpdateBuffer {
public:
    struct Entry {
        uint32_t key = 0;  // pair index + 1; 0 = empty slot
        uint32_t visible = 0, traced = 0;
    };

    void record(uint64_t pair, bool visible) { add(pair, visible ? 1u : 0u, 1u); }
    // Adds already-summed outcomes (merging other buffers).
    void add(uint64_t pair, uint32_t visible, uint32_t traced);
    template <typename F> void for_each(F &&f) const {
        for (const Entry &e : slots_)
            if (e.key) f(uint64_t(e.key - 1), e.visible, e.traced);
    }
    size_t size() const { return size_; }
    // Room for n pairs without growing (a merge of several buffers sizes its table once, not by doubling).
    void reserve(size_t n);
    void clear();

private:
    void rehash(size_t slots);  // to this many slots (a power of two, room for what it holds)
    std::vector<Entry> slots_;
    size_t size_ = 0;
};

}  // namespace neepp
