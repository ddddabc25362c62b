#include "neepp/io/checksum.h"

namespace neepp {

uint64_t fnv1a64(const void *data, size_t bytes, uint64_t hash) {
    const unsigned char *p = static_cast<const unsigned char *>(data);
    for (size_t i = 0; i < bytes; ++i) {
        hash ^= p[i];
        hash *= 0x100000001b3ULL;
    }
    return hash;
}

}  // namespace neepp
