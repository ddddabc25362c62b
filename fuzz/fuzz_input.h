// What every fuzz target shares: the readers under test take a path, so each input is written to a file
// of this process's own scratch folder first.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace neepp::fuzz {

// This process's scratch folder (created once, removed by nobody: the fuzzer exits with _exit).
inline const std::filesystem::path &scratch_dir() {
    static const std::filesystem::path dir = [] {
        auto d = std::filesystem::temp_directory_path() / ("neepp-fuzz-" + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

// Writes the input to scratch_dir()/name and returns its path.
inline std::string write_input(const uint8_t *data, size_t size, const std::string &name) {
    const std::filesystem::path p = scratch_dir() / name;
    std::ofstream(p, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char *>(data), std::streamsize(size));
    return p.string();
}

// With NEEPP_FUZZ_WRITE_SEED=DIR set, calls write(DIR), which writes the target's built-in seed inputs
// there, and exits: scripts/fuzz.sh starts each target's corpus this way (from LLVMFuzzerInitialize).
template <typename Write> void write_seeds_if_asked(Write &&write) {
    if (const char *dir = std::getenv("NEEPP_FUZZ_WRITE_SEED")) {
        std::filesystem::create_directories(dir);
        write(std::filesystem::path(dir));
        std::exit(0);
    }
}

// Writes text to dir/name (a seed).
inline void write_seed(const std::filesystem::path &dir, const std::string &name, const std::string &text) {
    std::ofstream(dir / name, std::ios::binary) << text;
}

}  // namespace neepp::fuzz
