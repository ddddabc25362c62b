// Layout from Mitsuba 3's src/shapes/serialized.cpp (its documentation and its reader of versions 3 and
// 4). Mitsuba reads the zlib stream only as far as it needs, so this does too: bytes after the last
// array (another mesh, the offset table) are never inflated.
#include "neepp/io/serialized_reader.h"
#include "neepp/io/binary_io.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <zlib.h>

namespace neepp {

namespace {

static_assert(std::endian::native == std::endian::little, "the .serialized reader assumes a little-endian host");

constexpr uint16_t kMagic = 0x041C;
constexpr uint32_t kHasNormals = 0x0001, kHasTexcoords = 0x0002, kHasColors = 0x0008, kDoublePrecision = 0x2000;
// Deflate expands at most about 1032:1; a count that would need more output than the rest of the file
// can hold is a corrupt header, refused before it reaches an allocation.
constexpr double kMaxInflateRatio = 1100;

// The zlib stream of one mesh, inflated on demand.
class Inflater {
public:
    Inflater(const std::string &data, size_t begin, const std::string &path) : path_(path) {
        zs_.next_in = reinterpret_cast<Bytef *>(const_cast<char *>(data.data() + begin));
        // At most 4 GiB of input is handed to zlib (uInt); a mesh larger than that is not expected.
        zs_.avail_in = uInt(std::min<size_t>(data.size() - begin, 0xFFFFFFFFu));
        if (inflateInit(&zs_) != Z_OK) throw SceneError(path_, "cannot start zlib decompression");
    }
    ~Inflater() { inflateEnd(&zs_); }
    Inflater(const Inflater &) = delete;
    Inflater &operator=(const Inflater &) = delete;

    void read(void *dst, size_t n) {
        auto *out = static_cast<Bytef *>(dst);
        while (n > 0) {
            const uInt chunk = uInt(std::min<size_t>(n, 1u << 30));
            zs_.next_out = out;
            zs_.avail_out = chunk;
            while (zs_.avail_out > 0) {
                if (ended_) throw SceneError(path_, "truncated .serialized file (a mesh's data ends early)");
                const int r = inflate(&zs_, Z_NO_FLUSH);
                if (r == Z_STREAM_END) ended_ = true;
                else if (r == Z_BUF_ERROR || (r == Z_OK && zs_.avail_in == 0 && zs_.avail_out > 0))
                    throw SceneError(path_, "truncated .serialized file (the compressed data ends early)");
                else if (r != Z_OK)
                    throw SceneError(path_, std::string("corrupt .serialized file (zlib: ") +
                                                (zs_.msg ? zs_.msg : "error " + std::to_string(r)) + ")");
            }
            out += chunk;
            n -= chunk;
        }
    }
    template <typename T> T get() {
        T v;
        read(&v, sizeof(T));
        return v;
    }
    // How many values of `bytes_each` the rest of the input could at most inflate to.
    double capacity(size_t bytes_each) const { return (double(zs_.avail_in) + 64) * kMaxInflateRatio / bytes_each; }

private:
    z_stream zs_{};
    const std::string &path_;
    bool ended_ = false;
};

// `count * dim` floats or doubles, as floats.
std::vector<float> read_reals(Inflater &in, bool double_precision, size_t count) {
    std::vector<float> values(count);
    if (!double_precision) {
        in.read(values.data(), count * sizeof(float));
        return values;
    }
    std::vector<double> d(count);
    in.read(d.data(), count * sizeof(double));
    std::transform(d.begin(), d.end(), values.begin(), [](double x) { return float(x); });
    return values;
}

std::vector<Vec3> read_vec3s(Inflater &in, bool double_precision, size_t count) {
    const std::vector<float> r = read_reals(in, double_precision, 3 * count);
    std::vector<Vec3> v(count);
    for (size_t i = 0; i < count; ++i) v[i] = Vec3(r[3 * i], r[3 * i + 1], r[3 * i + 2]);
    return v;
}

// Where mesh `shape_index` starts, from the offset table at the end of the file.
size_t mesh_offset(const std::string &data, int shape_index, uint16_t version, const std::string &path) {
    if (shape_index == 0) return 0;  // as Mitsuba, the first mesh is read without the table
    const size_t size = data.size();
    const uint32_t count = load_at<uint32_t>(data, size - 4);
    if (uint32_t(shape_index) >= count)
        throw SceneError(path, "shape_index " + std::to_string(shape_index) + " is out of range: the file holds " +
                                   std::to_string(count) + (count == 1 ? " mesh" : " meshes"));
    const size_t entry = version == 4 ? 8 : 4;  // version 3 stores 32-bit offsets
    const size_t table = size_t(count) * entry + 4;
    if (table > size) throw SceneError(path, "corrupt .serialized file (its offset table is larger than the file)");
    const size_t at = size - table + size_t(shape_index) * entry;
    const uint64_t offset = version == 4 ? load_at<uint64_t>(data, at) : load_at<uint32_t>(data, at);
    if (offset > size - table || size - table - offset < 4 || load_at<uint16_t>(data, offset) != kMagic)
        throw SceneError(path, "corrupt .serialized file (the offset table entry of mesh " + std::to_string(shape_index) +
                                   " points to no mesh)");
    return size_t(offset);
}

}  // namespace

MeshData read_serialized(const std::string &path, int shape_index) {
    if (shape_index < 0) throw SceneError(path, "shape_index must be non-negative (got " + std::to_string(shape_index) + ")");
    const std::string data = mesh_detail::read_file(path);
    if (data.size() < 4) throw SceneError(path, "truncated .serialized file (no header)");
    if (load_at<uint16_t>(data, 0) != kMagic) throw SceneError(path, "not a Mitsuba .serialized file (bad magic number)");
    const uint16_t version = load_at<uint16_t>(data, 2);
    if (version != 3 && version != 4)
        throw SceneError(path, "unsupported .serialized version " + std::to_string(version) +
                                   " (Mitsuba 3 up to 3.9 reads versions 3 and 4)");

    Inflater in(data, mesh_offset(data, shape_index, version, path) + 4, path);
    const uint32_t flags = in.get<uint32_t>();
    if (version == 4)
        while (in.get<char>() != 0) {}  // the mesh's name, null-terminated
    const uint64_t vertex_count = in.get<uint64_t>(), face_count = in.get<uint64_t>();
    const bool dp = flags & kDoublePrecision;
    const size_t real = dp ? sizeof(double) : sizeof(float);
    if (vertex_count > in.capacity(3 * real) || face_count > in.capacity(3 * sizeof(uint32_t)) || vertex_count > UINT32_MAX)
        throw SceneError(path, "corrupt .serialized file (it claims " + std::to_string(vertex_count) + " vertices and " +
                                   std::to_string(face_count) + " triangles, more than its data can hold)");

    MeshData m;
    m.positions = read_vec3s(in, dp, vertex_count);
    if (flags & kHasNormals) m.normals = read_vec3s(in, dp, vertex_count);
    if (flags & kHasTexcoords) {
        const std::vector<float> r = read_reals(in, dp, 2 * vertex_count);
        m.uvs.resize(vertex_count);
        for (size_t i = 0; i < vertex_count; ++i) m.uvs[i] = Vec2(r[2 * i], r[2 * i + 1]);
    }
    if (flags & kHasColors) read_reals(in, dp, 3 * vertex_count);  // skipped, as Mitsuba does (a zlib stream cannot seek)
    m.indices.resize(face_count * 3);
    in.read(m.indices.data(), m.indices.size() * sizeof(uint32_t));
    mesh_detail::finish_mesh(m, path);
    return m;
}

}  // namespace neepp
