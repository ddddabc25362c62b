// Little helpers for the project's own binary files (visibility maps, render checkpoints): values are
// appended and read back in this machine's byte order, with a clear error on a file too short.
#pragma once
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace neepp {

// The value of type T stored at byte `at` of `data`, in this machine's byte order; the caller has checked
// that sizeof(T) bytes are there (the mesh and volume readers check a whole header at once).
template <typename T> T load_at(const std::string &data, size_t at) {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    std::memcpy(&v, data.data() + at, sizeof(T));
    return v;
}

struct BinaryWriter {
    std::string bytes;
    template <typename T> void put(const T &v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes.append(reinterpret_cast<const char *>(&v), sizeof(T));
    }
    // A count, then the elements.
    template <typename T> void put_vector(const std::vector<T> &v) {
        static_assert(std::is_trivially_copyable_v<T>);
        put(uint64_t(v.size()));
        bytes.append(reinterpret_cast<const char *>(v.data()), v.size() * sizeof(T));
    }
    void put_string(const std::string &s) {
        put(uint64_t(s.size()));
        bytes.append(s);
    }
};

struct BinaryReader {
    std::string_view bytes;
    size_t pos = 0;
    std::string what;  // prefix of errors, e.g. "visibility map 'a.map'"
    template <typename T> T get() {
        static_assert(std::is_trivially_copyable_v<T>);
        need(sizeof(T));
        T v;
        std::memcpy(&v, bytes.data() + pos, sizeof(T));
        pos += sizeof(T);
        return v;
    }
    template <typename T> std::vector<T> get_vector() {
        const uint64_t n = get<uint64_t>();
        if (n > (bytes.size() - pos) / sizeof(T)) throw std::runtime_error(what + ": file is truncated");
        std::vector<T> v(n);
        if (n > 0) std::memcpy(v.data(), bytes.data() + pos, n * sizeof(T));  // an empty vector's data() may be null
        pos += n * sizeof(T);
        return v;
    }
    std::string get_string() {
        const uint64_t n = get<uint64_t>();
        need(n);
        std::string s(bytes.substr(pos, n));
        pos += n;
        return s;
    }
    void need(size_t n) const {
        if (n > bytes.size() - pos) throw std::runtime_error(what + ": file is truncated");
    }
};

// The whole file, or std::runtime_error("<what>: cannot open").
inline std::string read_file_bytes(const std::string &path, const std::string &what) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(what + ": cannot open");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace neepp
