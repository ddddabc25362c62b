// A render's progress, reported while it runs by a background thread that polls the fraction done: as a
// one-line terminal bar with elapsed time and ETA, as plain log lines (for a log file or a batch system,
// where a redrawn line would be a wall of carriage returns), and/or to a listener (the Python package's
// progress callback).
#pragma once
#include <atomic>
#include <chrono>
#include <functional>
#include <thread>

namespace neepp {

enum class ProgressStyle { none, bar, log };

class ProgressBar {
public:
    // fraction() is polled a few times a second and must be thread-safe; listener (if any) gets every
    // polled fraction and the elapsed seconds, on the polling thread.
    ProgressBar(std::function<double()> fraction, ProgressStyle style,
                std::function<void(double fraction, double elapsed_s)> listener = {});
    ~ProgressBar();
    void finish();

private:
    void draw(bool final_line);
    std::function<double()> fraction_;
    ProgressStyle style_;
    std::function<void(double, double)> listener_;
    std::atomic<bool> done_{false};
    std::chrono::steady_clock::time_point start_;
    double last_log_s_ = 0;
    int last_log_tenth_ = 0;
    std::thread thread_;
};

}  // namespace neepp
