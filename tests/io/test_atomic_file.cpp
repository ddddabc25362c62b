#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <sys/wait.h>
#include <unistd.h>

#include "../common/temp_dir.h"
#include "neepp/io/atomic_file.h"
#include "neepp/io/image.h"

using namespace neepp;

namespace {

std::string read_all(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

size_t files_in(const std::filesystem::path &dir) {
    size_t n = 0;
    for ([[maybe_unused]] auto &e : std::filesystem::directory_iterator(dir)) ++n;
    return n;
}

}  // namespace

TEST(AtomicFile, ReplacesTheFileAndLeavesNothingElse) {
    neepp::testing::TempDir tmp;
    const std::string path = tmp.write("stats.json", "old");
    write_file_atomically(path, std::string("new content"));
    EXPECT_EQ(read_all(path), "new content");
    EXPECT_EQ(files_in(tmp.dir), 1u);
}

TEST(AtomicFile, AFailedWriteKeepsTheOldFileAndRemovesItsTemporary) {
    neepp::testing::TempDir tmp;
    const std::string path = tmp.write("image.exr", "the previous image");
    EXPECT_THROW(write_file_atomically(path,
                                       [](const std::string &temporary) {
                                           std::ofstream(temporary) << "half an ima";
                                           throw std::runtime_error("disk full");
                                       }),
                 std::runtime_error);
    EXPECT_EQ(read_all(path), "the previous image");
    EXPECT_EQ(files_in(tmp.dir), 1u);
}

TEST(AtomicFile, AMissingFolderIsAnErrorNamingThePath) {
    neepp::testing::TempDir tmp;
    const std::string path = (tmp.dir / "no" / "such" / "a.json").string();
    try {
        write_file_atomically(path, std::string("x"));
        FAIL() << "expected an error";
    } catch (const std::runtime_error &e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

TEST(AtomicFile, ImagesAreWrittenThroughIt) {
    // write_exr and write_png_srgb replace their file whole: an image that cannot be encoded leaves the
    // previous file as it was.
    neepp::testing::TempDir tmp;
    const std::string exr = tmp.write("a.exr", "previous");
    Image bad(2, 2, 3);
    bad.data.resize(3);  // inconsistent: refused before anything is written
    EXPECT_THROW(write_exr(exr, bad), std::runtime_error);
    EXPECT_EQ(read_all(exr), "previous");
    Image img(4, 3, 3);
    write_exr(exr, img);
    write_png_srgb((tmp.dir / "a.png").string(), img);
    EXPECT_EQ(read_image(exr).width, 4);
    EXPECT_EQ(read_image((tmp.dir / "a.png").string()).height, 3);
    EXPECT_EQ(files_in(tmp.dir), 2u);
}

// A render killed by SIGKILL leaves its hidden temporary: the next write of the same output removes it,
// but never a temporary of a process still running (another render writing there), nor another output's.
TEST(AtomicFile, StaleTemporariesOfDeadProcessesAreRemovedAtTheNextWrite) {
    neepp::testing::TempDir tmp;
    const std::string path = (tmp.dir / "image.exr").string();
    // A process that has exited (and been waited for): its pid names no process now.
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) _exit(0);
    ASSERT_EQ(waitpid(child, nullptr, 0), child);
    const std::string dead = tmp.write(".image.exr." + std::to_string(child) + ".tmp", "half-written");
    const std::string live = tmp.write(".image.exr." + std::to_string(getppid()) + ".tmp", "being written");
    const std::string other = tmp.write(".other.exr." + std::to_string(child) + ".tmp", "another output's");
    const std::string not_ours = tmp.write(".image.exr.backup.tmp", "a user's");
    write_file_atomically(path, std::string("new"));
    EXPECT_EQ(read_all(path), "new");
    EXPECT_FALSE(std::filesystem::exists(dead));
    EXPECT_TRUE(std::filesystem::exists(live));
    EXPECT_TRUE(std::filesystem::exists(other));
    EXPECT_TRUE(std::filesystem::exists(not_ours));
}
