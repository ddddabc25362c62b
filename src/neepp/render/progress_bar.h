// A one-line terminal progress bar with elapsed time and ETA, redrawn by a background thread.
#pragma once
#include <atomic>
#include <chrono>
#include <functional>
#include <thread>

namespace neepp {

class ProgressBar {
public:
    // fraction() is polled a few times a second and must be thread-safe.
    explicit ProgressBar(std::function<double()> fraction, bool enabled);
    ~ProgressBar();
    void finish();

private:
    void draw(bool final_line);
    std::function<double()> fraction_;
    bool enabled_;
    std::atomic<bool> done_{false};
    std::chrono::steady_clock::time_point start_;
    std::thread thread_;
};

}  // namespace neepp
