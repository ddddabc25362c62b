#include "neepp/render/huge_pages.h"

#include <climits>
#include <cstdlib>
#include <utility>
#include <unistd.h>

namespace neepp {

namespace {
constexpr const char *kTunable = "glibc.malloc.hugetlb";
// With huge pages, every block glibc maps on its own (those over the mmap threshold, 128 KB to 32 MB,
// adjusted as it goes) is a fresh mapping whose 2 MB pages the kernel zeroes whole on first touch, and
// loading a scene allocates and frees many such blocks (a mesh's arrays, growing as it is parsed; decoded
// images), so a load would spend a noticeable part of its time zeroing pages. Blocks under 32 MB therefore
// come from the heap, and freed memory stays there (up to 256 MB at its top) for the next ones.
constexpr std::pair<const char *, const char *> kWith[] = {{"glibc.malloc.mmap_threshold", "33554432"},
                                                           {"glibc.malloc.trim_threshold", "268435456"}};
}  // namespace

std::string tunables_with_huge_pages(const char *current) {
    std::string tunables = current ? current : "";
    if (tunables.find(kTunable) != std::string::npos) return {};
    auto add = [&](const std::string &name, const char *value) {
        if (tunables.find(name) != std::string::npos) return;  // the user's value stays
        tunables += (tunables.empty() ? "" : ":") + name + "=" + value;
    };
    add(kTunable, "1");
    for (const auto &[name, value] : kWith) add(name, value);
    return tunables;
}

void restart_with_huge_pages(char **argv) {
    if (std::getenv("NEEPP_NO_HUGE_PAGES")) return;
    const char *current = std::getenv("GLIBC_TUNABLES");
    const std::string tunables = tunables_with_huge_pages(current);
    if (tunables.empty()) return;
    const std::string saved = current ? current : "";
    setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
    // By the executable's own path, not /proc/self/exe: the kernel names a process after the file it
    // runs, and ps, top and pkill would otherwise list the render as "exe".
    char path[PATH_MAX];
    const ssize_t len = readlink("/proc/self/exe", path, sizeof(path) - 1);
    path[len > 0 ? len : 0] = '\0';
    execv(len > 0 ? path : "/proc/self/exe", argv);  // returns only if the restart failed: go on with 4 KB pages
    if (current) setenv("GLIBC_TUNABLES", saved.c_str(), 1);
    else unsetenv("GLIBC_TUNABLES");
}

bool malloc_huge_pages() {
    const char *t = std::getenv("GLIBC_TUNABLES");
    if (!t) return false;
    const std::string tunables = t, key = std::string(kTunable) + "=";
    const size_t at = tunables.find(key);
    if (at == std::string::npos) return false;
    const size_t value = at + key.size();
    return value < tunables.size() && tunables[value] != '0';
}

}  // namespace neepp
