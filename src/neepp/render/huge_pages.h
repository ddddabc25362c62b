// Transparent huge pages for the render's large arrays. A render reads meshes, textures, Embree's BVH and
// NEE++'s visibility map at random, and with 4 KB pages most of those reads also miss the TLB (a texture
// prefetch's page walk is among the costliest instructions of a render). glibc's allocator can
// advise the kernel to back its large blocks with 2 MB pages (the glibc.malloc.hugetlb=1 tunable; the
// kernel's THP mode "madvise", Debian's default, honours it), but it reads its tunables only when a
// process starts: the command-line tool therefore restarts itself once with the tunable added.
#pragma once
#include <string>

namespace neepp {

// GLIBC_TUNABLES as given, with glibc.malloc.hugetlb=1 added unless it already sets that tunable
// (whatever its value: a user's choice is kept). Empty when nothing is to be added.
std::string tunables_with_huge_pages(const char *current);

// Re-executes this program (/proc/self/exe, same arguments) with the tunable added; returns (doing
// nothing) when it is already there, when NEEPP_NO_HUGE_PAGES is set, or when the restart fails.
void restart_with_huge_pages(char **argv);

// Whether glibc was started with huge pages for its large blocks (for the statistics file).
bool malloc_huge_pages();

}  // namespace neepp
