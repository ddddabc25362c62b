#include "neepp/render/progress_bar.h"

#include <algorithm>
#include <cstdio>
#include <string>

namespace neepp {

ProgressBar::ProgressBar(std::function<double()> fraction, ProgressStyle style,
                         std::function<void(double, double)> listener)
    : fraction_(std::move(fraction)), style_(style), listener_(std::move(listener)),
      start_(std::chrono::steady_clock::now()) {
    if (style_ == ProgressStyle::none && !listener_) return;
    thread_ = std::thread([this] {
        while (!done_.load()) {
            draw(false);
            for (int i = 0; i < 5 && !done_.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
    });
}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::finish() {
    if (done_.exchange(true)) return;
    if (thread_.joinable()) thread_.join();
    if (style_ != ProgressStyle::none || listener_) draw(true);
}

static std::string format_seconds(double s) {
    char buf[32];
    if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
    else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
    return buf;
}

void ProgressBar::draw(bool final_line) {
    double f = std::clamp(fraction_(), 0.0, 1.0);
    double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (listener_) listener_(f, elapsed);
    std::string eta = f > 0.005 ? format_seconds(elapsed * (1 - f) / f) : "?";
    if (style_ == ProgressStyle::bar) {
        constexpr int width = 40;
        int filled = int(f * width);
        std::string bar(filled, '=');
        if (filled < width) bar += '>' + std::string(width - filled - 1, ' ');
        std::fprintf(stderr, "\r[%s] %5.1f%% %s elapsed, ETA %s   ", bar.c_str(), 100 * f,
                     format_seconds(elapsed).c_str(), eta.c_str());
        if (final_line) std::fprintf(stderr, "\n");
        std::fflush(stderr);
    } else if (style_ == ProgressStyle::log) {
        // A line per tenth of the render (at most one every 2 s) and at least one a minute, and the last.
        const int tenth = int(f * 10);
        const bool due = (tenth > last_log_tenth_ && elapsed - last_log_s_ >= 2) || elapsed - last_log_s_ >= 60;
        if (!due && !final_line) return;
        last_log_s_ = elapsed;
        last_log_tenth_ = tenth;
        std::fprintf(stderr, "neepp: %5.1f%% done, %s elapsed, ETA %s\n", 100 * f, format_seconds(elapsed).c_str(),
                     final_line ? "0.0s" : eta.c_str());
        std::fflush(stderr);
    }
}

}  // namespace neepp
