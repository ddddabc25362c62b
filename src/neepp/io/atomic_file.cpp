#include "neepp/io/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <unistd.h>
#include <fmt/format.h>

namespace neepp {
namespace {

// Hidden, and named for this process so two renders writing the same output never share one.
std::string temporary_name(const std::string &path) {
    const std::filesystem::path p(path);
    return (p.parent_path() / fmt::format(".{}.{}.tmp", p.filename().string(), getpid())).string();
}

// fsync, so that the rename cannot reach the disk before the data does (after a crash the name would
// then point to an empty file on some file systems).
bool flush_to_disk(const std::string &file) {
    const int fd = ::open(file.c_str(), O_RDONLY);
    if (fd < 0) return false;
    const bool ok = ::fsync(fd) == 0;
    ::close(fd);
    return ok;
}

}  // namespace

void write_file_atomically(const std::string &path, const std::function<void(const std::string &)> &write) {
    const std::string tmp = temporary_name(path);
    try {
        write(tmp);
        if (!flush_to_disk(tmp))
            throw std::runtime_error(fmt::format("'{}': cannot flush the written file to disk: {}", path, std::strerror(errno)));
        if (std::rename(tmp.c_str(), path.c_str()) != 0)
            throw std::runtime_error(fmt::format("'{}': cannot rename the written file to it: {}", path, std::strerror(errno)));
    } catch (...) {
        std::remove(tmp.c_str());
        throw;
    }
}

void write_file_atomically(const std::string &path, const std::string &content) {
    write_file_atomically(path, [&](const std::string &tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out.write(content.data(), std::streamsize(content.size()));
        out.close();
        if (!out) throw std::runtime_error(fmt::format("'{}': cannot write", path));
    });
}

}  // namespace neepp
