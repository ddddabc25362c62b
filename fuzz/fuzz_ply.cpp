// The PLY reader (ascii and both binary encodings) on arbitrary bytes: a SceneError is the expected answer to a bad file; anything else
// (a crash, a sanitizer report, a hang, a leak, memory out of proportion to the input) is a bug.
#include <algorithm>
#include <cstring>
#include <exception>
#include "fuzz_input.h"
#include "neepp/io/ply_reader.h"

namespace {

// A header for n vertices with x y z nx ny nz u v and one face list, in the given encoding.
std::string header(const char *format, const char *index_type) {
    return std::string("ply\nformat ") + format + " 1.0\ncomment seed\nelement vertex 3\nproperty float x\n"
           "property float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
           "property float u\nproperty float v\nelement face 1\nproperty list uchar " + index_type +
           " vertex_indices\nend_header\n";
}

template <typename T> void put(std::string &s, T v, bool big_endian) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big_endian) std::reverse(b, b + sizeof(T));
    s.append(b, sizeof(T));
}

std::string binary(bool big_endian) {
    std::string s = header(big_endian ? "binary_big_endian" : "binary_little_endian", "int");
    const float v[3][8] = {{0, 0, 0, 0, 0, 1, 0, 0}, {1, 0, 0, 0, 0, 1, 1, 0}, {0, 1, 0, 0, 0, 1, 0, 1}};
    for (const auto &row : v)
        for (float f : row) put(s, f, big_endian);
    s.push_back(char(3));
    for (int32_t i : {0, 1, 2}) put(s, i, big_endian);
    return s;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        neepp::fuzz::write_seed(dir, "ascii.ply", header("ascii", "uint") + "0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n"
                                                  "0 1 0 0 0 1 0 1\n3 0 1 2\n");
        neepp::fuzz::write_seed(dir, "little.ply", binary(false));
        neepp::fuzz::write_seed(dir, "big.ply", binary(true));
    });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    try {
        neepp::read_ply(neepp::fuzz::write_input(data, size, "mesh.ply"));
    } catch (const std::exception &) {
    }
    return 0;
}
