// A scratch folder for the files a test writes, removed when the test is done.
#pragma once
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace neepp::testing {

struct TempDir {
    std::filesystem::path dir;
    TempDir() {
        dir = std::filesystem::temp_directory_path() / ("neepp_test_" + std::to_string(std::random_device{}()));
        std::filesystem::create_directories(dir);
    }
    ~TempDir() { std::filesystem::remove_all(dir); }
    TempDir(const TempDir &) = delete;
    TempDir &operator=(const TempDir &) = delete;
    // Writes the bytes to dir/name (creating sub-folders) and returns the full path.
    std::string write(const std::string &name, const std::string &bytes) const {
        std::filesystem::path p = dir / name;
        std::filesystem::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << bytes;
        return p.string();
    }
};

}  // namespace neepp::testing
