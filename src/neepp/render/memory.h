// What this process may still allocate, so that a render too large for the machine is refused with a
// clear error before it starts instead of being ended by the kernel's OOM killer halfway through (Linux
// overcommits: a 100 GB film "allocates" fine and fails only as its pages are touched).
#pragma once
#include <cstdint>

namespace neepp {

// Bytes this process can still allocate: the kernel's MemAvailable, lowered to what is left under the
// cgroup's memory.max (containers, CI) and the address-space limit (ulimit -v) where those are set.
uint64_t available_memory_bytes();

// Throws std::runtime_error, saying how much is needed and how much there is, when a film of width ×
// height pixels cannot be held (bytes_per_pixel: what the render loop keeps per pixel).
void check_film_fits_in_memory(int width, int height, uint64_t bytes_per_pixel);

}  // namespace neepp
