// Visibility-map files on arbitrary bytes, against a fixed 4^3 grid. The harness gives every input a
// valid checksum (its last 8 bytes), or hardly any mutation would get past that check to the structure
// checks behind it; a damaged checksum's refusal is the unit tests' (tests/visibility/test_map_file.cpp).
// Its seed is a valid map for this grid.
#include <cstring>
#include <vector>
#include <exception>
#include "fuzz_input.h"
#include "neepp/visibility/map_file.h"

namespace {

const neepp::VoxelGrid &grid() {
    static const neepp::VoxelGrid g(neepp::BBox{neepp::Vec3(-1.f), neepp::Vec3(1.f)}, 4);
    return g;
}
constexpr uint64_t kFingerprint = 0x6e65657070667a7aULL;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        neepp::VisibilityMap map(grid().cell_count());
        for (uint32_t a = 0; a < grid().cell_count(); a += 3)
            for (uint32_t b = a; b < grid().cell_count(); b += 7) map.add(a, b, (a + b) % 17, 16);
        neepp::save_visibility_map((dir / "seed.map").string(), grid(), map, kFingerprint);
    });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    std::vector<uint8_t> bytes(data, data + size);
    if (size >= 16) {
        const uint64_t sum = neepp::fnv1a64(bytes.data(), size - 8);
        std::memcpy(bytes.data() + size - 8, &sum, 8);
    }
    try {
        neepp::load_visibility_map(neepp::fuzz::write_input(bytes.data(), size, "visibility.map"), grid(), kFingerprint);
    } catch (const std::exception &) {
    }
    return 0;
}
