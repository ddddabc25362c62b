#include "neepp/visibility/update_buffer.h"

namespace neepp {

namespace {
inline uint32_t slot_hash(uint32_t key) {
    key ^= key >> 16; key *= 0x7feb352dU; key ^= key >> 15; key *= 0x846ca68bU; key ^= key >> 16;
    return key;
}
}  // namespace

void PairUpdateBuffer::add(uint64_t pair, uint32_t visible, uint32_t traced) {
    if (2 * (size_ + 1) > slots_.size()) rehash(slots_.empty() ? 1024 : 2 * slots_.size());  // load factor <= 1/2
    const uint32_t key = uint32_t(pair) + 1, mask = uint32_t(slots_.size() - 1);
    for (uint32_t i = slot_hash(key) & mask;; i = (i + 1) & mask) {
        Entry &e = slots_[i];
        if (e.key == key || e.key == 0) {
            if (e.key == 0) { e.key = key; ++size_; }
            e.visible += visible;
            e.traced += traced;
            // A uint32 count cannot overflow in one pass in practice (4 G rays per pair per thread).
            return;
        }
    }
}

void PairUpdateBuffer::reserve(size_t n) {
    size_t slots = slots_.empty() ? 1024 : slots_.size();
    while (2 * n > slots) slots *= 2;  // load factor <= 1/2, as add() keeps it
    if (slots > slots_.size()) rehash(slots);
}

void PairUpdateBuffer::rehash(size_t slots) {
    std::vector<Entry> old = std::move(slots_);
    slots_.assign(slots, Entry{});
    const uint32_t mask = uint32_t(slots_.size() - 1);
    for (const Entry &e : old) {
        if (!e.key) continue;
        uint32_t i = slot_hash(e.key) & mask;
        while (slots_[i].key) i = (i + 1) & mask;
        slots_[i] = e;
    }
}

void PairUpdateBuffer::clear() {
    // Keep the capacity: the next pass touches about the same pairs.
    for (Entry &e : slots_) e = Entry{};
    size_ = 0;
}

}  // namespace neepp
