// The checksum of the project's binary files (visibility maps, render checkpoints).
#pragma once
#include <cstddef>
#include <cstdint>

namespace neepp {

// 64-bit FNV-1a: no new dependency, and it detects any single flipped byte.
uint64_t fnv1a64(const void *data, size_t bytes, uint64_t hash = 0xcbf29ce484222325ULL);

}  // namespace neepp
