// The command-line tool's huge-page set-up: the tunables are added to what the user set, never overrides a
// choice of theirs, and the statistics read back whether it is on.
#include <gtest/gtest.h>

#include <cstdlib>

#include "neepp/render/huge_pages.h"

using namespace neepp;

TEST(HugePages, TunableIsAddedToWhatIsSet) {
    const std::string added =
        "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=268435456";
    EXPECT_EQ(tunables_with_huge_pages(nullptr), added);
    EXPECT_EQ(tunables_with_huge_pages(""), added);
    EXPECT_EQ(tunables_with_huge_pages("glibc.malloc.arena_max=2"), "glibc.malloc.arena_max=2:" + added);
    // A threshold the user chose is kept.
    EXPECT_EQ(tunables_with_huge_pages("glibc.malloc.mmap_threshold=65536"),
              "glibc.malloc.mmap_threshold=65536:glibc.malloc.hugetlb=1:glibc.malloc.trim_threshold=268435456");
    // Already chosen, on or off: nothing to add (and so no restart).
    EXPECT_EQ(tunables_with_huge_pages("glibc.malloc.hugetlb=0"), "");
    EXPECT_EQ(tunables_with_huge_pages("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1"), "");
}

TEST(HugePages, StatisticsReadTheTunable) {
    const char *saved = std::getenv("GLIBC_TUNABLES");
    const std::string keep = saved ? saved : "";
    unsetenv("GLIBC_TUNABLES");
    EXPECT_FALSE(malloc_huge_pages());
    setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1", 1);
    EXPECT_TRUE(malloc_huge_pages());
    setenv("GLIBC_TUNABLES", "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=0", 1);
    EXPECT_FALSE(malloc_huge_pages());
    setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=", 1);
    EXPECT_FALSE(malloc_huge_pages());
    if (saved) setenv("GLIBC_TUNABLES", keep.c_str(), 1);
    else unsetenv("GLIBC_TUNABLES");
}
