// One lazily built value per voxel, safe to read from the render threads: the first reader of a voxel
// builds its value; concurrent first readers may both build it and one result is kept, which is only
// correct because a value depends on nothing but (voxel, state frozen for the pass). clear() drops
// every value and must only run between passes. With an array type (LazyVoxelArray<double[]>) a value
// is a block of elements, held without an object around it: one cache miss less per read.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <type_traits>

namespace neepp {

template <class T>
class LazyVoxelArray {
    using Element = std::remove_extent_t<T>;

public:
    explicit LazyVoxelArray(uint32_t voxel_count) : count_(voxel_count), values_(new std::atomic<Element *>[voxel_count]) {
        for (uint32_t v = 0; v < count_; ++v) values_[v].store(nullptr, std::memory_order_relaxed);
    }
    ~LazyVoxelArray() { clear(); }
    LazyVoxelArray(const LazyVoxelArray &) = delete;
    LazyVoxelArray &operator=(const LazyVoxelArray &) = delete;

    // build(voxel) -> std::unique_ptr<T>, called only when the voxel has no value yet. The value, or
    // for an array type its first element.
    template <class Build>
    decltype(auto) get(uint32_t voxel, Build &&build) const {
        return deref(fetch(voxel, std::forward<Build>(build)));
    }
    void clear() {
        for (uint32_t v = 0; v < count_; ++v) std::default_delete<T>()(values_[v].exchange(nullptr));
    }
    uint64_t built() const { return built_.load(std::memory_order_relaxed); }  // over the array's life

private:
    template <class Build>
    const Element *fetch(uint32_t voxel, Build &&build) const {
        if (Element *t = values_[voxel].load(std::memory_order_acquire)) return t;
        std::unique_ptr<T> fresh = build(voxel);
        Element *expected = nullptr;
        if (values_[voxel].compare_exchange_strong(expected, fresh.get(), std::memory_order_acq_rel)) {
            built_.fetch_add(1, std::memory_order_relaxed);
            return fresh.release();
        }
        return expected;  // another thread built the same value first
    }
    static decltype(auto) deref(const Element *t) {
        if constexpr (std::is_array_v<T>) return t;
        else return static_cast<const T &>(*t);
    }

    uint32_t count_;
    std::unique_ptr<std::atomic<Element *>[]> values_;
    mutable std::atomic<uint64_t> built_{0};
};

}  // namespace neepp
