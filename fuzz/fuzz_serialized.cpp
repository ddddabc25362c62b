// The .serialized reader on arbitrary bytes: a SceneError is the expected answer to a bad file; anything
// else (a crash, a sanitizer report, a hang, a leak, memory out of proportion to the input) is a bug.
// The first byte chooses how the rest is read: bit 0 clear, as the whole file; set, as a mesh's
// decompressed data, which the harness compresses behind a header (version 3 when bit 3 is set, else 4),
// so that mutations reach the checks of counts, flags and arrays instead of stopping at zlib's. Bits 1-2
// are the shape_index asked for.
#include <exception>
#include "common/serialized_writer.h"
#include "fuzz_input.h"
#include "neepp/io/serialized_reader.h"

namespace {

using neepp::testing::SerializedTestMesh;

SerializedTestMesh triangle(bool double_precision) {
    SerializedTestMesh m;
    m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    m.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    m.uvs = {0, 0, 1, 0, 0, 1};
    m.colors = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    m.indices = {0, 1, 2};
    m.double_precision = double_precision;
    return m;
}

// A file's first mesh, decompressed: what the harness compresses for a first byte with bit 0 set.
std::string payload(const std::string &file) {
    std::string raw(1024, '\0');
    uLongf size = uLongf(raw.size());
    uncompress(reinterpret_cast<Bytef *>(raw.data()), &size, reinterpret_cast<const Bytef *>(file.data() + 4),
               uLong(file.size() - 4));
    raw.resize(size);
    return raw;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        using neepp::testing::serialized;
        for (uint16_t version : {3, 4}) {
            const std::string v = std::to_string(version);
            const std::string two = serialized({triangle(false), triangle(true)}, version);
            neepp::fuzz::write_seed(dir, "file_v" + v + "_index0.serialized", std::string(1, char(0)) + two);
            neepp::fuzz::write_seed(dir, "file_v" + v + "_index1.serialized", std::string(1, char(2)) + two);
            for (bool dp : {false, true})
                neepp::fuzz::write_seed(dir, "payload_v" + v + (dp ? "_double" : "_single") + ".bin",
                                        std::string(1, char(version == 3 ? 9 : 1)) + payload(serialized({triangle(dp)}, version)));
        }
    });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size == 0) return 0;
    const uint8_t mode = data[0];
    std::string file(reinterpret_cast<const char *>(data + 1), size - 1);
    if (mode & 1) {
        std::string header;
        neepp::testing::put_le(header, uint16_t(0x041C));
        neepp::testing::put_le(header, uint16_t(mode & 8 ? 3 : 4));
        file = header + neepp::testing::deflate(file);
    }
    try {
        neepp::read_serialized(neepp::fuzz::write_input(reinterpret_cast<const uint8_t *>(file.data()), file.size(),
                                                        "mesh.serialized"),
                               (mode >> 1) & 3);
    } catch (const std::exception &) {
    }
    return 0;
}
