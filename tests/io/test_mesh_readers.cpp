// OBJ and PLY readers: Mitsuba semantics on small hand-written files, error cases, and every mesh
// the shared scenes reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include "neepp/io/obj_reader.h"
#include "neepp/io/ply_reader.h"
#include "neepp/io/xml_tree.h"
#include "common/temp_dir.h"

using namespace neepp;
using neepp::testing::TempDir;
namespace fs = std::filesystem;

namespace {


// Expects a SceneError whose message starts with the path and contains `needle`.
template <class F>
void expect_error(F &&f, const std::string &path, const std::string &needle) {
    try {
        f();
        ADD_FAILURE() << "expected a SceneError containing \"" << needle << "\"";
    } catch (const SceneError &e) {
        std::string msg = e.what();
        EXPECT_EQ(msg.rfind(path + ":", 0), 0u) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
}

std::vector<uint32_t> tri(std::initializer_list<uint32_t> v) { return v; }

// ---- OBJ ----

TEST(ObjReader, QuadsNegativeIndicesGroupsAndUvFlip) {
    TempDir tmp;
    std::string path = tmp.write("quad.obj", R"(# two groups, one mesh
mtllib missing.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 0.25
vt 0 1
vn 0 0 2
g first
usemtl whatever
f 1/1/1 2/2/1 3/3/1 4/4/1
g second
f -4/-4/-1 -2/-2/-1 -1/-1/-1
f 1/3/1 2/2/1 3/3/1
)");
    MeshData m = read_obj(path);
    // Corners with the same (position, uv, normal) indices share a vertex; position 1 with uv 3 is new.
    ASSERT_EQ(m.positions.size(), 5u);
    EXPECT_EQ(m.indices, tri({0, 1, 2, 0, 2, 3, 0, 2, 3, 4, 1, 2}));
    EXPECT_EQ(m.positions[4], Vec3(0, 0, 0));
    ASSERT_EQ(m.uvs.size(), 5u);
    EXPECT_FLOAT_EQ(m.uvs[2].x, 1.f);
    EXPECT_FLOAT_EQ(m.uvs[2].y, 0.75f);  // v flipped: 1 - 0.25
    EXPECT_FLOAT_EQ(m.uvs[3].y, 0.f);
    ASSERT_EQ(m.normals.size(), 5u);
    EXPECT_EQ(m.normals[0], Vec3(0, 0, 1));  // normalized
}

TEST(ObjReader, FansPolygonsAndOmitsAbsentAttributes) {
    TempDir tmp;
    std::string path = tmp.write("penta.obj", "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\r\nv 0 1 0\nf 1 2 3 4 5\nf 1 2\n");
    MeshData m = read_obj(path);
    EXPECT_EQ(m.positions.size(), 5u);
    EXPECT_EQ(m.indices, tri({0, 1, 2, 0, 2, 3, 0, 3, 4}));
    EXPECT_TRUE(m.uvs.empty());
    EXPECT_TRUE(m.normals.empty());
}

TEST(ObjReader, RejectsBadFiles) {
    TempDir tmp;
    std::string nan = tmp.write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    expect_error([&] { read_obj(nan); }, nan + ":2", "NaN");
    std::string inf = tmp.write("inf.obj", "v 0 0 1e999\n");
    expect_error([&] { read_obj(inf); }, inf + ":1", "infinite");
    std::string range = tmp.write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    expect_error([&] { read_obj(range); }, range + ":4", "vertex 4");
    std::string uv_range = tmp.write("uv.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n");
    expect_error([&] { read_obj(uv_range); }, uv_range, "texture coordinate 2");
    std::string word = tmp.write("word.obj", "v 0 zero 0\n");
    expect_error([&] { read_obj(word); }, word + ":1", "could not parse");
    std::string corner = tmp.write("corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2x 3\n");
    expect_error([&] { read_obj(corner); }, corner + ":4", "malformed face");
    std::string missing = (tmp.dir / "absent.obj").string();
    expect_error([&] { read_obj(missing); }, missing, "cannot open");
}

// ---- PLY ----

// Writes PLY files with the same content in any of the three encodings.
class PlyWriter {
public:
    explicit PlyWriter(std::string format) : format_(std::move(format)) {}
    void header(const std::string &lines) { header_ = lines; }
    template <class T>
    PlyWriter &put(T v) {
        if (format_ == "ascii") {
            body_ += std::to_string(+v) + " ";
            return *this;
        }
        char bytes[sizeof(T)];
        std::memcpy(bytes, &v, sizeof(T));
        bool big = format_ == "binary_big_endian";
        if (big == (std::endian::native == std::endian::little)) std::reverse(bytes, bytes + sizeof(T));
        body_.append(bytes, sizeof(T));
        return *this;
    }
    void end_record() {
        if (format_ == "ascii") body_ += "\n";
    }
    std::string bytes() const { return "ply\nformat " + format_ + " 1.0\n" + header_ + "end_header\n" + body_; }

private:
    std::string format_, header_, body_;
};

// A quad plus a triangle, with normals, s/t texture coordinates, and things to skip: an extra
// uchar vertex property, an unknown element with variable-length lists, and an extra face property.
std::string sample_ply(const std::string &format) {
    PlyWriter w(format);
    w.header(
        "comment made by a test\n"
        "element vertex 5\n"
        "property float x\nproperty float y\nproperty double z\n"
        "property uchar quality\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "property float s\nproperty float t\n"
        "element material 2\n"
        "property list uchar short ids\nproperty int flags\n"
        "element face 2\n"
        "property int32 tag\n"
        "property list uint8 uint vertex_indices\n");
    const float pos[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0.5f}};
    for (int k = 0; k < 5; ++k) {
        w.put(pos[k][0]).put(pos[k][1]).put(double(pos[k][2])).put(uint8_t(200 + k));
        w.put(0.f).put(0.f).put(3.f);
        w.put(0.25f * k).put(0.125f * k);
        w.end_record();
    }
    w.put(uint8_t(3)).put(short(1)).put(short(-2)).put(short(3)).put(int32_t(7));
    w.end_record();
    w.put(uint8_t(0)).put(int32_t(-1));
    w.end_record();
    w.put(int32_t(42)).put(uint8_t(4)).put(uint32_t(0)).put(uint32_t(1)).put(uint32_t(2)).put(uint32_t(3));
    w.end_record();
    w.put(int32_t(43)).put(uint8_t(3)).put(uint32_t(1)).put(uint32_t(4)).put(uint32_t(2));
    w.end_record();
    return w.bytes();
}

TEST(PlyReader, AllEncodingsGiveTheSameMesh) {
    TempDir tmp;
    MeshData ascii = read_ply(tmp.write("a.ply", sample_ply("ascii")));
    ASSERT_EQ(ascii.positions.size(), 5u);
    EXPECT_EQ(ascii.indices, tri({0, 1, 2, 0, 2, 3, 1, 4, 2}));
    EXPECT_EQ(ascii.positions[4], Vec3(2, 0, 0.5f));
    ASSERT_EQ(ascii.normals.size(), 5u);
    EXPECT_EQ(ascii.normals[3], Vec3(0, 0, 1));  // normalized
    ASSERT_EQ(ascii.uvs.size(), 5u);
    EXPECT_FLOAT_EQ(ascii.uvs[2].x, 0.5f);
    EXPECT_FLOAT_EQ(ascii.uvs[2].y, 0.25f);  // not flipped for PLY, as in Mitsuba

    for (const char *format : {"binary_little_endian", "binary_big_endian"}) {
        SCOPED_TRACE(format);
        MeshData m = read_ply(tmp.write(std::string(format) + ".ply", sample_ply(format)));
        EXPECT_EQ(m.indices, ascii.indices);
        ASSERT_EQ(m.positions.size(), ascii.positions.size());
        for (size_t k = 0; k < m.positions.size(); ++k) {
            EXPECT_EQ(m.positions[k], ascii.positions[k]);
            EXPECT_EQ(m.normals[k], ascii.normals[k]);
            EXPECT_EQ(m.uvs[k].x, ascii.uvs[k].x);
            EXPECT_EQ(m.uvs[k].y, ascii.uvs[k].y);
        }
    }
}

// Properties Mitsuba does not read itself become attributes, grouped by its rules: r g b (a) is
// vertex_color, prefix_0/1/2 and prefix_x/y/z runs of 1 or 3 are vertex_prefix, prefix_r/g/b is
// vertex_prefix_color; runs of 2, or out of sequence, are dropped. Values are kept as stored (no
// division of integer colours by 255). A face's values go to each triangle the face becomes.
TEST(PlyReader, GroupsOtherPropertiesIntoAttributesAsMitsubaDoes) {
    TempDir tmp;
    const std::string ply = R"(ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
property uchar red
property uchar green
property uchar blue
property float w_0
property float w_1
property float w_2
property float pair_x
property float pair_y
property float t_r
property float t_g
property float t_b
property float single_x
property float bad_x
property float bad_z
property float u
property float v
element face 2
property float weight_0
property list uchar int vertex_indices
property float tint_x
property float tint_y
property float tint_z
end_header
0 0 0 255 0 0 1 2 3 9 9 0.1 0.2 0.3 7 8 8 0 0
1 0 0 0 255 0 4 5 6 9 9 0.4 0.5 0.6 7 8 8 1 0
1 1 0 0 0 255 7 8 9 9 9 0.7 0.8 0.9 7 8 8 1 1
0 1 0 1 2 3 10 11 12 9 9 1 1 1 7 8 8 0 1
0.5 4 0 1 2 3 0.1 0.2 0.3
0.25 3 0 2 3 1 1 1
)";
    const MeshData m = read_ply(tmp.write("attrs.ply", ply));
    ASSERT_EQ(m.triangle_count(), 3u);
    ASSERT_EQ(m.uvs.size(), 4u);
    std::vector<std::string> names;
    for (const MeshAttribute &a : m.attributes) names.push_back(a.name + "/" + std::to_string(a.dim));
    EXPECT_EQ(names, (std::vector<std::string>{"vertex_color/3", "vertex_w/3", "vertex_t_color/3", "vertex_single/1",
                                               "face_weight/1", "face_tint/3"}));
    EXPECT_EQ(m.attributes[0].values, (std::vector<float>{255, 0, 0, 0, 255, 0, 0, 0, 255, 1, 2, 3}));
    EXPECT_EQ(m.attributes[1].values[5], 6.f);
    EXPECT_FLOAT_EQ(m.attributes[2].values[7], 0.8f);
    EXPECT_EQ(m.attributes[3].values, (std::vector<float>{7, 7, 7, 7}));
    EXPECT_EQ(m.attributes[4].values, (std::vector<float>{0.5f, 0.5f, 0.25f}));  // the quad's two triangles
    EXPECT_FLOAT_EQ(m.attributes[5].values[3 * 1 + 2], 0.3f);
    EXPECT_FLOAT_EQ(m.attributes[5].values[3 * 2 + 0], 1.f);
    EXPECT_TRUE(m.attributes[4].per_face());
    EXPECT_FALSE(m.attributes[0].per_face());
}

TEST(PlyReader, RejectsBadFiles) {
    TempDir tmp;
    std::string good = sample_ply("binary_little_endian");
    std::string cut = tmp.write("cut.ply", good.substr(0, good.size() - 3));
    expect_error([&] { read_ply(cut); }, cut, "truncated");
    std::string trailing = tmp.write("trailing.ply", good + "xx");
    expect_error([&] { read_ply(trailing); }, trailing, "after the last");
    std::string cut_ascii = tmp.write("cut_ascii.ply", sample_ply("ascii").substr(0, sample_ply("ascii").size() - 4));
    expect_error([&] { read_ply(cut_ascii); }, cut_ascii, "truncated");
    std::string no_end = tmp.write("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\n");
    expect_error([&] { read_ply(no_end); }, no_end, "end_header");
    std::string bad_type = tmp.write("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n");
    expect_error([&] { read_ply(bad_type); }, bad_type + ":4", "unknown property type \"quad\"");
    std::string not_ply = tmp.write("not.ply", "v 0 0 0\n");
    expect_error([&] { read_ply(not_ply); }, not_ply, "not a PLY file");
    std::string xyz = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uchar int vertex_index\nend_header\n";
    std::string nan = tmp.write("nan.ply", xyz + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
    expect_error([&] { read_ply(nan); }, nan, "NaN");
    std::string range = tmp.write("range.ply", xyz + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    expect_error([&] { read_ply(range); }, range, "vertex 3");
    std::string missing = (tmp.dir / "absent.ply").string();
    expect_error([&] { read_ply(missing); }, missing, "cannot open");
}

// ---- The shared scenes' meshes ----

TEST(MeshReaders, ReadEveryMeshOfTheSharedScenes) {
    fs::path scenes = fs::path(NEEPP_SHARED_DIR) / "scenes";
    if (!fs::exists(scenes)) GTEST_SKIP() << "no shared scenes at " << scenes;
    size_t files = 0, triangles = 0;
    for (const char *name : {"bathroom", "classroom", "cornell-box", "living-room", "staircase", "veach-ajar"}) {
        auto root = parse_mitsuba_xml((scenes / name / "scene.xml").string());
        std::set<std::string> seen;
        for (const auto &shape : root->children_with_tag("shape")) {
            if (shape->type != "obj" && shape->type != "ply") continue;
            std::string file = shape->resolve_path(shape->get_string("filename"));
            if (!seen.insert(file).second) continue;
            SCOPED_TRACE(file);
            MeshData m = shape->type == "obj" ? read_obj(file) : read_ply(file);
            ++files;
            triangles += m.triangle_count();
            EXPECT_GT(m.triangle_count(), 0u);
            EXPECT_EQ(m.indices.size() % 3, 0u);
            EXPECT_TRUE(m.normals.empty() || m.normals.size() == m.positions.size());
            EXPECT_TRUE(m.uvs.empty() || m.uvs.size() == m.positions.size());
            // finish_mesh already rejects non-finite data and bad indices; check the invariant anyway.
            EXPECT_TRUE(std::all_of(m.positions.begin(), m.positions.end(), [](const Vec3 &p) { return is_finite(p); }));
            EXPECT_TRUE(std::all_of(m.indices.begin(), m.indices.end(), [&](uint32_t i) { return i < m.positions.size(); }));
        }
    }
    EXPECT_GT(files, 1000u);
    EXPECT_GT(triangles, 1000000u);
    std::cout << "read " << files << " mesh files, " << triangles << " triangles\n";
}

}  // namespace
