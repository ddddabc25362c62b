// Which render a checkpoint belongs to: --resume refuses another render's checkpoint naming what differs,
// and a distributed render's checkpoint and a single machine's each name the command that resumes them;
// a finished render's checkpoint goes with what killed saves of it left. Files of version 2 (before the
// distributed driver's part) still read.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cstring>
#include <filesystem>
#include "common/temp_dir.h"
#include "neepp/io/checksum.h"
#include "neepp/render/checkpoint_identity.h"

using namespace neepp;

namespace {

RenderCheckpoint checkpoint_of(const nlohmann::json &identity) {
    RenderCheckpoint c;
    c.identity = identity.dump();
    c.spp = 3;
    c.passes = 2;
    c.image_sums = {1, 2, 3, 4};
    return c;
}

std::string refusal(const std::string &path, const nlohmann::json &identity) {
    try {
        checkpoint_to_resume(path, identity);
    } catch (const std::runtime_error &e) {
        return e.what();
    }
    return "(accepted)";
}

TEST(CheckpointIdentity, AnotherRenderIsRefusedNamingWhatDiffers) {
    neepp::testing::TempDir tmp;
    const std::string path = (tmp.dir / "a.exr.checkpoint").string();
    const nlohmann::json mine = {{"seed", 3}, {"film", "48x32"}};
    save_checkpoint(path, checkpoint_of(mine));
    EXPECT_EQ(checkpoint_to_resume(path, mine).spp, 3);
    EXPECT_NE(refusal(path, {{"seed", 4}, {"film", "48x32"}}).find("of another render: its seed is 3, this render's is 4"),
              std::string::npos);
    EXPECT_NE(refusal((tmp.dir / "none").string(), mine).find("no checkpoint"), std::string::npos);
}

TEST(CheckpointIdentity, DistributedAndSingleMachineCheckpointsNameTheCommandThatResumesThem) {
    neepp::testing::TempDir tmp;
    const nlohmann::json one = {{"seed", 3}};
    nlohmann::json distributed = one;
    distributed["distributed"] = {{"workers", 4}, {"budget", "16 spp"}};
    const std::string single_path = (tmp.dir / "one.checkpoint").string(), ray_path = (tmp.dir / "ray.checkpoint").string();
    save_checkpoint(single_path, checkpoint_of(one));
    save_checkpoint(ray_path, checkpoint_of(distributed));
    const std::string a = refusal(ray_path, one);
    EXPECT_NE(a.find("is of a distributed render"), std::string::npos) << a;
    EXPECT_NE(a.find("resume it with --ray --workers 4"), std::string::npos) << a;
    const std::string b = refusal(single_path, distributed);
    EXPECT_NE(b.find("is of a render on one machine"), std::string::npos) << b;
    EXPECT_NE(b.find("without --ray"), std::string::npos) << b;
    nlohmann::json other_workers = distributed;
    other_workers["distributed"]["workers"] = 2;
    const std::string c = refusal(ray_path, other_workers);
    EXPECT_NE(c.find("of another render: its distributed is"), std::string::npos) << c;
    EXPECT_EQ(checkpoint_to_resume(ray_path, distributed).spp, 3);
}

TEST(CheckpointIdentity, TheDriversPartRoundTripsAndVersion2Reads) {
    neepp::testing::TempDir tmp;
    RenderCheckpoint c = checkpoint_of({{"seed", 3}});
    c.driver = R"({"rounds":{"rounds":3}})";
    const std::string path = (tmp.dir / "a.checkpoint").string();
    save_checkpoint(path, c);
    EXPECT_EQ(load_checkpoint(path).driver, c.driver);
    // Version 2: the same fields without the driver's part (its empty string's length), checksummed anew.
    c.driver.clear();
    std::string bytes = checkpoint_bytes(c);
    std::string v2 = bytes.substr(0, bytes.size() - 16);
    const uint32_t version = 2;
    std::memcpy(v2.data() + 8, &version, 4);
    const uint64_t sum = fnv1a64(v2.data(), v2.size());
    v2.append(reinterpret_cast<const char *>(&sum), 8);
    const RenderCheckpoint old = load_checkpoint(tmp.write("v2.checkpoint", v2));
    EXPECT_EQ(old.spp, 3);
    EXPECT_EQ(old.image_sums, c.image_sums);
    EXPECT_TRUE(old.driver.empty());
}

TEST(CheckpointIdentity, RemovingAFinishedRendersCheckpointRemovesWhatKilledSavesLeft) {
    neepp::testing::TempDir tmp;
    const std::string path = (tmp.dir / "a.exr.checkpoint").string();
    save_checkpoint(path, checkpoint_of({{"seed", 3}}));
    const pid_t child = fork();  // a process that has exited: its pid names no process now
    ASSERT_GE(child, 0);
    if (child == 0) _exit(0);
    ASSERT_EQ(waitpid(child, nullptr, 0), child);
    const std::string stale = tmp.write(".a.exr.checkpoint." + std::to_string(child) + ".tmp", "half-written");
    remove_checkpoint(path);
    EXPECT_FALSE(std::filesystem::exists(path));
    EXPECT_FALSE(std::filesystem::exists(stale));
}

}  // namespace
