#include "neepp/io/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <csignal>
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

// Temporaries of this output that a process killed while writing (SIGKILL, a power cut) left behind:
// removed when the output is next written. Only those whose process is gone: a live one (another render
// writing the same output, this one's other threads) may still be writing its own.
void remove_stale_temporaries(const std::string &path) {
    const std::filesystem::path p(path);
    const std::string prefix = "." + p.filename().string() + ".", suffix = ".tmp";
    std::error_code ec;
    const std::filesystem::path dir = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
            name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
            continue;
        const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
        if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
        const pid_t pid = pid_t(std::stol(digits));
        // kill(pid, 0) fails with ESRCH only when no such process exists (EPERM: it exists, another user's).
        if (pid <= 0 || pid == getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
        std::error_code ignored;
        std::filesystem::remove(it->path(), ignored);
    }
}

void write_file_atomically(const std::string &path, const std::function<void(const std::string &)> &write) {
    const std::string tmp = temporary_name(path);
    remove_stale_temporaries(path);
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
