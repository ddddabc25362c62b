#include "neepp/render/memory.h"

#include <algorithm>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <sys/resource.h>
#include <fmt/format.h>

namespace neepp {
namespace {

constexpr uint64_t kUnlimited = std::numeric_limits<uint64_t>::max();

// A cgroup v2 file holding a byte count, or kUnlimited ("max", or no such file: cgroup v1 or none).
uint64_t read_cgroup_bytes(const char *name) {
    std::ifstream in(std::string("/sys/fs/cgroup/") + name);
    std::string v;
    if (!(in >> v) || v == "max") return kUnlimited;
    try {
        return std::stoull(v);
    } catch (const std::exception &) {
        return kUnlimited;
    }
}

}  // namespace

uint64_t available_memory_bytes() {
    uint64_t available = kUnlimited;
    if (std::ifstream meminfo("/proc/meminfo"); meminfo) {
        std::string key;
        uint64_t kb;
        std::string unit;
        while (meminfo >> key >> kb) {
            std::getline(meminfo, unit);
            if (key == "MemAvailable:") {
                available = kb * 1024;
                break;
            }
        }
    }
    const uint64_t cg_max = read_cgroup_bytes("memory.max"), cg_used = read_cgroup_bytes("memory.current");
    if (cg_max != kUnlimited && cg_used != kUnlimited) available = std::min(available, cg_max > cg_used ? cg_max - cg_used : 0);
    rlimit as{};
    if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) available = std::min<uint64_t>(available, as.rlim_cur);
    return available;
}

void check_film_fits_in_memory(int width, int height, uint64_t bytes_per_pixel) {
    const uint64_t needed = uint64_t(width) * uint64_t(height) * bytes_per_pixel, available = available_memory_bytes();
    if (needed > available)
        throw std::runtime_error(fmt::format(
            "the {}x{} film needs {:.1f} GB of memory for its buffers ({} bytes per pixel), more than the {:.1f} GB "
            "available: render a smaller film (e.g. -D resx=... -D resy=... where the scene declares them)",
            width, height, double(needed) * 1e-9, bytes_per_pixel, double(available) * 1e-9));
}

}  // namespace neepp
