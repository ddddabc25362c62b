#include "neepp/render/huge_pages.h"

#include <cstdlib>
#include <unistd.h>

namespace neepp {

namespace {
constexpr const char *kTunable = "glibc.malloc.hugetlb";
}

std::string tunables_with_huge_pages(const char *current) {
    const std::string tunables = current ? current : "";
    if (tunables.find(kTunable) != std::string::npos) return {};
    return tunables.empty() ? std::string(kTunable) + "=1" : tunables + ":" + kTunable + "=1";
}

void restart_with_huge_pages(char **argv) {
    if (std::getenv("NEEPP_NO_HUGE_PAGES")) return;
    const char *current = std::getenv("GLIBC_TUNABLES");
    const std::string tunables = tunables_with_huge_pages(current);
    if (tunables.empty()) return;
    const std::string saved = current ? current : "";
    setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
    execv("/proc/self/exe", argv);  // returns only if the restart failed: go on with 4 KB pages
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
