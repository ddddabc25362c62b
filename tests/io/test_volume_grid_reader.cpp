// The .vol reader on files written here in Mitsuba's layout, and its errors on bad, truncated and
// unsupported files: each names the file.
#include <gtest/gtest.h>

#include "common/temp_dir.h"
#include "common/volume_grid_writer.h"
#include "neepp/io/scene_error.h"
#include "neepp/io/volume_grid_reader.h"

using namespace neepp;
using neepp::testing::TempDir;
using neepp::testing::VolumeGridFile;
using neepp::testing::volume_grid_bytes;

namespace {

// 3 x 2 x 4 points of 2 channels: value = 100 z + 10 y + x, and its negative in the second channel.
VolumeGridFile two_channel_grid() {
    VolumeGridFile g;
    g.size[0] = 3, g.size[1] = 2, g.size[2] = 4, g.channels = 2;
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 3; ++x) {
                g.values.push_back(float(100 * z + 10 * y + x));
                g.values.push_back(-float(100 * z + 10 * y + x));
            }
    g.bounds = {-1, -2, -3, 4, 5, 6};
    return g;
}

void expect_error(const std::string &path, const std::string &needle) {
    try {
        read_volume_grid(path);
        ADD_FAILURE() << "expected a SceneError containing \"" << needle << "\"";
    } catch (const SceneError &e) {
        const std::string msg = e.what();
        EXPECT_EQ(msg.rfind(path + ":", 0), 0u) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
}

}  // namespace

TEST(VolumeGridReader, ReadsSizesChannelsBoundsAndValuesInMitsubasOrder) {
    TempDir tmp;
    const VolumeGrid g = read_volume_grid(tmp.write("grid.vol", volume_grid_bytes(two_channel_grid())));
    EXPECT_EQ(g.size[0], 3u);
    EXPECT_EQ(g.size[1], 2u);
    EXPECT_EQ(g.size[2], 4u);
    EXPECT_EQ(g.channels, 2u);
    EXPECT_EQ(g.bounds.lo, Vec3(-1, -2, -3));
    EXPECT_EQ(g.bounds.hi, Vec3(4, 5, 6));
    ASSERT_EQ(g.values.size(), 48u);
    EXPECT_EQ(g.at(2, 1, 3), 312.f);
    EXPECT_EQ(g.at(2, 1, 3, 1), -312.f);
    EXPECT_EQ(g.at(1, 0, 2), 201.f);
    EXPECT_EQ(g.warning, "");
    // Bytes after the values are ignored, as Mitsuba ignores them, and said (the loader warns).
    const VolumeGrid longer = read_volume_grid(tmp.write("longer.vol", volume_grid_bytes(two_channel_grid()) + "tail"));
    EXPECT_EQ(longer.values, g.values);
    EXPECT_NE(longer.warning.find("4 bytes after the 3 x 2 x 4 points of 2 channels"), std::string::npos) << longer.warning;
}

// A header that gives fewer values than the file holds: Mitsuba reads the first ones, so neepp does, but
// a data size that is a whole multiple of the header's says which mistake it likely is.
TEST(VolumeGridReader, DataBeyondTheHeadersShapeIsSaid) {
    TempDir tmp;
    VolumeGridFile g = two_channel_grid();
    g.channels = 1;  // the data has two per point
    const VolumeGrid one = read_volume_grid(tmp.write("one.vol", volume_grid_bytes(g)));
    EXPECT_EQ(one.values.size(), 24u);
    EXPECT_NE(one.warning.find("96 bytes after the 3 x 2 x 4 points of 1 channel that the header gives"), std::string::npos)
        << one.warning;
    EXPECT_NE(one.warning.find("exactly 2 times as many values: is the size or the channel count wrong?"), std::string::npos)
        << one.warning;
    g = two_channel_grid();
    g.size[2] = 3;  // 48 values written, 36 read: not a multiple
    const VolumeGrid short_z = read_volume_grid(tmp.write("short_z.vol", volume_grid_bytes(g)));
    EXPECT_NE(short_z.warning.find("48 bytes after"), std::string::npos) << short_z.warning;
    EXPECT_EQ(short_z.warning.find("times as many"), std::string::npos) << short_z.warning;
}

TEST(VolumeGridReader, BadFilesAreRefusedNamingTheFile) {
    TempDir tmp;
    expect_error((tmp.dir / "missing.vol").string(), "cannot open");
    expect_error(tmp.write("empty.vol", ""), "does not start with 'VOL'");
    expect_error(tmp.write("text.vol", "solid cube\n"), "does not start with 'VOL'");
    VolumeGridFile g = two_channel_grid();
    g.version = 2;
    expect_error(tmp.write("v2.vol", volume_grid_bytes(g)), "version 2");
    g = two_channel_grid();
    g.data_type = 3;  // uint8 in Mitsuba 0.6, which Mitsuba 3 refuses
    expect_error(tmp.write("uint8.vol", volume_grid_bytes(g)), "data type 3");
    g = two_channel_grid();
    g.size[1] = 0;
    expect_error(tmp.write("zero.vol", volume_grid_bytes(g)), "3 x 0 x 4");
    g = two_channel_grid();
    g.size[2] = -5;
    expect_error(tmp.write("negative.vol", volume_grid_bytes(g)), "is invalid");
    g = two_channel_grid();
    g.channels = 0;
    expect_error(tmp.write("nochannel.vol", volume_grid_bytes(g)), "0 channels");
    const std::string whole = volume_grid_bytes(two_channel_grid());
    expect_error(tmp.write("header.vol", whole.substr(0, 30)), "header ends early");
    expect_error(tmp.write("values.vol", whole.substr(0, whole.size() - 1)), "truncated");
    // A header claiming 2^31^3 values is refused from the file's size, before anything is allocated.
    g = two_channel_grid();
    g.size[0] = g.size[1] = g.size[2] = 0x7FFFFFFF;
    expect_error(tmp.write("huge.vol", volume_grid_bytes(g)), "truncated");
}
