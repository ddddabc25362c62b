#include "neepp/display/tev_display.h"

#include <stdexcept>
#include "neepp/display/tev_packets.h"

namespace neepp {

using Clock = std::chrono::steady_clock;

TevDisplay::TevDisplay(const ServerAddress &server, std::string image_name, Warn warn, Settings settings)
    : server_(server), name_(std::move(image_name)), warn_(std::move(warn)), settings_(settings) {
    try {
        addresses_ = resolve_server_address(server_);
    } catch (const std::runtime_error &e) {
        warn_(std::string("display server ") + server_.text() + ": " + e.what() + "; rendering without it");
        warned_ = true;
    }
    thread_ = std::thread([this] { run(); });
}

TevDisplay::~TevDisplay() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        finishing_ = true;
        has_pending_ = false;  // not waited for: finish() is where the last image is waited for
    }
    stop_ = true;
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void TevDisplay::show(Image image) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (finishing_) return;
        pending_ = std::move(image);
        has_pending_ = true;
    }
    wake_.notify_all();
}

bool TevDisplay::finish(double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    finishing_ = true;
    wake_.notify_all();
    const bool in_time =
        wake_.wait_for(lock, std::chrono::duration<double>(std::max(timeout_s, 0.0)), [this] { return done_; });
    const bool sent = in_time && last_sent_;
    lock.unlock();
    if (!in_time) {
        stop_ = true;  // the thread gives up its connect or send where it is
        warn_(std::string("the display server ") + server_.text() + " did not take the final image within " +
              std::to_string(int(timeout_s)) + " s; stopped sending");
    }
    if (thread_.joinable()) thread_.join();
    return sent;
}

void TevDisplay::run() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        if (!has_pending_ && finishing_) break;
        const bool may_try = connection_.connected() || finishing_ || Clock::now() >= next_attempt_;
        if (!has_pending_ || !may_try) {
            // Until an image comes, finish() is called, or (an image waiting) the next try is due.
            if (has_pending_) wake_.wait_until(lock, next_attempt_);
            else wake_.wait(lock);
            continue;
        }
        Image image = std::move(pending_);
        has_pending_ = false;
        const bool last_try = finishing_;
        lock.unlock();
        const bool sent = !addresses_.empty() && !stop_ && deliver(image, last_try);
        lock.lock();
        last_sent_ = sent;
        if (sent) continue;
        if (last_try || addresses_.empty() || stop_) break;
        // Not sent (no viewer yet, or it went away): kept for the next try unless a newer one came.
        if (!has_pending_) {
            pending_ = std::move(image);
            has_pending_ = true;
        }
    }
    done_ = true;
    wake_.notify_all();
}

bool TevDisplay::connect(bool last_try) {
    next_attempt_ = Clock::now() + std::chrono::milliseconds(int(settings_.retry_interval_s * 1000));
    if (connection_.connect(addresses_, settings_.connect_timeout_ms, &stop_)) {
        created_width_ = created_height_ = created_channels_ = 0;  // a new connection may be a new tev
        return true;
    }
    if (!warned_ && !stop_) {
        warn_("cannot connect to the display server " + server_.text() + " (" + connection_.error() +
              "): rendering without it" + (last_try ? "" : "; neepp tries again every few seconds (is tev running "
                                                            "and listening there? tev --host " + server_.text() + ")"));
        warned_ = true;
    }
    return false;
}

bool TevDisplay::deliver(const Image &image, bool last_try) {
    if (!connection_.connected() && !connect(last_try)) return false;
    auto send = [&](const std::vector<uint8_t> &packet) {
        if (connection_.send_all(packet, settings_.stall_timeout_ms, &stop_)) return true;
        next_attempt_ = Clock::now() + std::chrono::milliseconds(int(settings_.retry_interval_s * 1000));
        if (!warned_ && !stop_) {
            warn_("lost the display server " + server_.text() + " (" + connection_.error() + "): rendering goes on without it");
            warned_ = true;
        }
        return false;
    };
    if (image.width != created_width_ || image.height != created_height_ || image.channels != created_channels_) {
        // Create (or re-create) the image, and show it: tev may have other images open.
        if (!send(tev::create_image_packet(name_, true, image.width, image.height, tev::channel_names(image.channels))))
            return false;
        created_width_ = image.width;
        created_height_ = image.height;
        created_channels_ = image.channels;
    }
    for (const tev::TileRect &t : tev::image_tiles(image.width, image.height, settings_.tile_size))
        if (!send(tev::update_image_packet(name_, false, image, t.x, t.y, t.w, t.h))) return false;
    ++images_sent_;
    return true;
}

}  // namespace neepp
