// Shows a render in tev (the HDR viewer) as it converges: `neepp render --display-server HOST:PORT`, as
// pbrt-v4's --display-server. The render hands over each image it wants shown and goes on at once; a
// thread of the display's own sends it, in tiles, over tev's protocol (tev_packets.h). Only the newest
// image waits to be sent, so a slow viewer sees fewer updates and never holds up the render, and an
// absent viewer or a lost connection is one warning, then a quiet new try every few seconds (tev may be
// started, or restarted, during the render).
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>
#include "neepp/display/tcp_connection.h"
#include "neepp/io/image.h"

namespace neepp {

class TevDisplay {
public:
    struct Settings {
        int tile_size = 128;             // pixels a side: 128 x 128 x RGB is a 192 KiB packet
        int connect_timeout_ms = 1000;   // per address
        int stall_timeout_ms = 10000;    // a viewer that takes no byte for this long is given up on
        double retry_interval_s = 2.0;   // between tries to connect
    };
    using Warn = std::function<void(const std::string &)>;

    // Shows images under `image_name` in the tev listening at `server`. Resolves the host name here,
    // before the render: a name that does not resolve is a warning, and nothing is sent.
    TevDisplay(const ServerAddress &server, std::string image_name, Warn warn, Settings settings);
    TevDisplay(const ServerAddress &server, std::string image_name, Warn warn)
        : TevDisplay(server, std::move(image_name), std::move(warn), Settings{}) {}
    ~TevDisplay();  // stops at once; finish() first to wait for the last image
    TevDisplay(const TevDisplay &) = delete;
    TevDisplay &operator=(const TevDisplay &) = delete;

    // Hands the image to the sending thread and returns at once; an image not yet sent is replaced.
    void show(Image image);
    // Waits, for at most timeout_s, until the last image shown has been sent (one more try to connect
    // included), then stops the thread. True when it reached the viewer; a warning says when it did not
    // because the time ran out.
    bool finish(double timeout_s);
    // Whole images sent (for tests and messages).
    int images_sent() const { return images_sent_.load(); }

private:
    void run();
    bool deliver(const Image &image, bool last_try);
    bool connect(bool last_try);

    const ServerAddress server_;
    const std::string name_;
    const Warn warn_;
    const Settings settings_;
    std::vector<SocketAddress> addresses_;  // empty: the name did not resolve, nothing is sent
    TcpConnection connection_;              // the thread's alone
    int created_width_ = 0, created_height_ = 0, created_channels_ = 0;  // the image tev has, this connection
    bool warned_ = false;                   // one warning about the viewer per render
    std::chrono::steady_clock::time_point next_attempt_{};

    std::mutex mutex_;
    std::condition_variable wake_;
    Image pending_;
    bool has_pending_ = false, finishing_ = false, done_ = false, last_sent_ = false;
    std::atomic<bool> stop_{false};  // ends a connect or a send where it is
    std::atomic<int> images_sent_{0};
    std::thread thread_;
};

}  // namespace neepp
