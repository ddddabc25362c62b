// The display's address, and its promise to the render: an absent or stalled viewer costs one warning
// and no wait beyond finish()'s time-out, and a viewer that reads gets exactly tev's packets.
#include <gtest/gtest.h>
#include <chrono>
#include <thread>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include "neepp/display/tev_display.h"
#include "neepp/display/tev_packets.h"

using namespace neepp;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A TCP socket bound to a free port of 127.0.0.1, listening when asked (a connection completes in the
// backlog without accept(), and then nothing reads it: a viewer that is stuck).
struct LoopbackSocket {
    int fd = -1;
    uint16_t port = 0;
    explicit LoopbackSocket(bool listening) {
        fd = socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        EXPECT_EQ(bind(fd, reinterpret_cast<sockaddr *>(&a), sizeof(a)), 0);
        socklen_t len = sizeof(a);
        getsockname(fd, reinterpret_cast<sockaddr *>(&a), &len);
        port = ntohs(a.sin_port);
        if (listening) {
            EXPECT_EQ(listen(fd, 4), 0);
        }
    }
    ~LoopbackSocket() { close(fd); }
    ServerAddress address() const { return {"127.0.0.1", port}; }
};

Image gradient(int w, int h) {
    Image image(w, h, 3);
    for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = 0.001f * float(i);
    return image;
}

}  // namespace

TEST(ServerAddress, ParsesHostAndPort) {
    ServerAddress a = parse_server_address("127.0.0.1:14158");
    EXPECT_EQ(a.host, "127.0.0.1");
    EXPECT_EQ(a.port, 14158);
    a = parse_server_address("render-box.local:1");
    EXPECT_EQ(a.host, "render-box.local");
    EXPECT_EQ(a.port, 1);
    a = parse_server_address("[::1]:65535");
    EXPECT_EQ(a.host, "::1");
    EXPECT_EQ(a.port, 65535);
    EXPECT_EQ(a.text(), "[::1]:65535");
}

TEST(ServerAddress, SaysWhatIsWrong) {
    const std::pair<const char *, const char *> bad[] = {
        {"localhost", "no port"},         {"localhost:", "no port after"},  {":14158", "no host"},
        {"localhost:0", "not in 1..65535"}, {"localhost:65536", "not in 1..65535"}, {"localhost:http", "not a number"},
        {"localhost:-1", "not a number"}, {"::1:14158", "brackets"},         {"[::1:14158", "closing"},
        {"[::1]", "no port"},
    };
    for (const auto &[text, why] : bad) {
        try {
            parse_server_address(text);
            ADD_FAILURE() << text << " was accepted";
        } catch (const std::invalid_argument &e) {
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << text << ": " << e.what();
        }
    }
}

TEST(TevDisplay, AnAbsentViewerIsOneWarningAndNoWait) {
    const ServerAddress nobody = LoopbackSocket(false).address();  // bound, never listening, then closed
    std::vector<std::string> warnings;
    const auto start = Clock::now();
    TevDisplay display(nobody, "absent.exr", [&](const std::string &w) { warnings.push_back(w); });
    for (int i = 0; i < 20; ++i) display.show(gradient(8, 4));
    EXPECT_FALSE(display.finish(5.0));
    EXPECT_LT(seconds_since(start), 2.0);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("cannot connect to the display server 127.0.0.1:"), std::string::npos) << warnings[0];
    EXPECT_EQ(display.images_sent(), 0);
}

TEST(TevDisplay, AStuckViewerHoldsUpNeitherShowNorFinishBeyondItsTimeOut) {
    LoopbackSocket stuck(true);  // accepts connections (in its backlog) and never reads
    std::vector<std::string> warnings;
    TevDisplay display(stuck.address(), "stuck.exr", [&](const std::string &w) { warnings.push_back(w); });
    const Image big = gradient(2048, 1024);  // 24 MiB: more than the socket buffers hold
    auto start = Clock::now();
    for (int i = 0; i < 3; ++i) display.show(big);
    EXPECT_LT(seconds_since(start), 1.0);  // show() only hands the image over
    start = Clock::now();
    EXPECT_FALSE(display.finish(0.5));
    EXPECT_LT(seconds_since(start), 2.0);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("did not take the final image"), std::string::npos) << warnings[0];
}

TEST(TevDisplay, AViewerThatReadsGetsTheImageCreatedThenInTiles) {
    LoopbackSocket viewer(true);
    std::vector<uint8_t> received;
    std::thread reader([&] {
        const int c = accept(viewer.fd, nullptr, nullptr);
        uint8_t buf[65536];
        for (ssize_t n; (n = read(c, buf, sizeof(buf))) > 0;) received.insert(received.end(), buf, buf + n);
        close(c);
    });
    const Image image = gradient(5, 3);
    std::vector<std::string> warnings;
    {
        TevDisplay::Settings settings;
        settings.tile_size = 2;
        TevDisplay display(viewer.address(), "out/render.exr", [&](const std::string &w) { warnings.push_back(w); }, settings);
        display.show(image);
        EXPECT_TRUE(display.finish(10.0));
        EXPECT_EQ(display.images_sent(), 1);
    }  // closes the connection: the reader sees its end
    reader.join();
    std::vector<uint8_t> expected = tev::create_image_packet("out/render.exr", true, 5, 3, {"R", "G", "B"});
    for (const tev::TileRect &t : tev::image_tiles(5, 3, 2)) {
        const std::vector<uint8_t> p = tev::update_image_packet("out/render.exr", false, image, t.x, t.y, t.w, t.h);
        expected.insert(expected.end(), p.begin(), p.end());
    }
    EXPECT_EQ(received, expected);
    EXPECT_TRUE(warnings.empty());
}
