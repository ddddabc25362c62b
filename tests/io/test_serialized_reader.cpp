// The .serialized reader on files written here in Mitsuba's layout (versions 3 and 4, single and double
// precision, several meshes with the offset table), and its errors on bad, truncated and corrupt files.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include "neepp/io/serialized_reader.h"
#include "common/serialized_writer.h"
#include "common/temp_dir.h"

using namespace neepp;
using neepp::testing::SerializedTestMesh;
using neepp::testing::TempDir;
using neepp::testing::deflate;
using neepp::testing::put_le;
using neepp::testing::serialized;

namespace {

SerializedTestMesh quad() {
    SerializedTestMesh m;
    m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    m.normals = {0, 0, 2, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    m.uvs = {0, 0, 1, 0, 1, 0.25f, 0, 1};
    m.colors = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

SerializedTestMesh triangle(float z) {
    SerializedTestMesh m;
    m.name = "triangle";
    m.positions = {0, 0, z, 2, 0, z, 0, 3, z};
    m.indices = {0, 1, 2};
    return m;
}

template <class F> void expect_error(F &&f, const std::string &path, const std::string &needle) {
    try {
        f();
        ADD_FAILURE() << "expected a SceneError containing \"" << needle << "\"";
    } catch (const SceneError &e) {
        const std::string msg = e.what();
        EXPECT_EQ(msg.rfind(path + ":", 0), 0u) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
}

}  // namespace

TEST(SerializedReader, ReadsEveryAttributeInBothVersionsAndPrecisions) {
    TempDir tmp;
    for (uint16_t version : {3, 4})
        for (bool dp : {false, true}) {
            SerializedTestMesh q = quad();
            q.double_precision = dp;
            const MeshData m = read_serialized(tmp.write("quad.serialized", serialized({q}, version)));
            SCOPED_TRACE(::testing::Message() << "version " << version << (dp ? " double" : " single"));
            ASSERT_EQ(m.positions.size(), 4u);
            EXPECT_EQ(m.positions[2], Vec3(1, 1, 0));
            ASSERT_EQ(m.normals.size(), 4u);
            EXPECT_EQ(m.normals[0], Vec3(0, 0, 1));  // normalized, as Mitsuba does
            ASSERT_EQ(m.uvs.size(), 4u);
            EXPECT_FLOAT_EQ(m.uvs[2].y, 0.25f);  // not flipped; the colours before the indices are skipped
            EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
        }
}

TEST(SerializedReader, ShapeIndexPicksAMeshThroughTheOffsetTable) {
    TempDir tmp;
    for (uint16_t version : {3, 4}) {
        const std::string path = tmp.write("three.serialized", serialized({quad(), triangle(1), triangle(2)}, version));
        EXPECT_EQ(read_serialized(path, 0).positions.size(), 4u);
        for (int k : {1, 2}) {
            const MeshData m = read_serialized(path, k);
            ASSERT_EQ(m.positions.size(), 3u);
            EXPECT_EQ(m.positions[1], Vec3(2, 0, float(k)));
            EXPECT_TRUE(m.normals.empty());
            EXPECT_TRUE(m.uvs.empty());
        }
        expect_error([&] { read_serialized(path, 3); }, path, "shape_index 3 is out of range: the file holds 3 meshes");
        expect_error([&] { read_serialized(path, -1); }, path, "shape_index must be non-negative");
    }
}

TEST(SerializedReader, BadFilesGiveClearErrors) {
    TempDir tmp;
    const std::string good = serialized({quad(), triangle(1)});
    auto error_of = [&](const std::string &name, const std::string &bytes, const std::string &needle, int index = 0) {
        const std::string path = tmp.write(name, bytes);
        expect_error([&] { read_serialized(path, index); }, path, needle);
    };
    expect_error([&] { read_serialized((tmp.dir / "missing.serialized").string()); }, (tmp.dir / "missing.serialized").string(),
                 "cannot open");
    error_of("empty.serialized", "", "truncated .serialized file (no header)");
    error_of("magic.serialized", "PLY!" + good.substr(4), "bad magic number");
    std::string v5 = good;
    v5[2] = 5;
    error_of("v5.serialized", v5, "unsupported .serialized version 5");
    // Cut inside the first mesh's compressed data, and right after its header.
    error_of("cut.serialized", good.substr(0, 30), "truncated .serialized file");
    error_of("header.serialized", good.substr(0, 4), "truncated .serialized file");
    std::string corrupt = good;
    for (size_t i = 6; i < 16; ++i) corrupt[i] = char(0xFF);
    error_of("corrupt.serialized", corrupt, "corrupt .serialized file (zlib:");
    // An offset table entry that points past the meshes.
    std::string table = good;
    const uint64_t far = 1u << 20;
    std::memcpy(table.data() + table.size() - 4 - 8, &far, 8);
    error_of("table.serialized", table, "offset table entry of mesh 1 points to no mesh", 1);
    // A count no data can back, and an index past the vertices.
    std::string raw;
    put_le(raw, uint32_t(0x1000));
    raw.push_back('\0');
    put_le(raw, uint64_t(1) << 40);
    put_le(raw, uint64_t(1));
    std::string bomb;
    put_le(bomb, uint16_t(0x041C));
    put_le(bomb, uint16_t(4));
    error_of("count.serialized", bomb + deflate(raw), "more than its data can hold");
    SerializedTestMesh bad_index = triangle(0);
    bad_index.indices = {0, 1, 3};
    error_of("index.serialized", serialized({bad_index}), "face references vertex 3 but there are only 3");
    SerializedTestMesh nan = triangle(0);
    nan.positions[4] = std::nanf("");
    error_of("nan.serialized", serialized({nan}), "vertex 1 has an invalid (NaN or infinite) position");
}
