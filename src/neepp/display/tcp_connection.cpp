#include "neepp/display/tcp_connection.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <unistd.h>

namespace neepp {

std::string ServerAddress::text() const {
    const bool ipv6 = host.find(':') != std::string::npos;
    return (ipv6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

ServerAddress parse_server_address(const std::string &text) {
    auto bad = [&](const std::string &why) {
        return std::invalid_argument("'" + text + "' is not HOST:PORT: " + why);
    };
    std::string host, port;
    if (!text.empty() && text[0] == '[') {  // [IPv6]:PORT
        const size_t close = text.find(']');
        if (close == std::string::npos) throw bad("the IPv6 address has no closing ']'");
        host = text.substr(1, close - 1);
        if (close + 1 >= text.size() || text[close + 1] != ':') throw bad("no port after the address (e.g. [::1]:14158)");
        port = text.substr(close + 2);
    } else {
        const size_t colon = text.rfind(':');
        if (colon == std::string::npos) throw bad("no port (tev listens on 127.0.0.1:14158 by default)");
        host = text.substr(0, colon);
        port = text.substr(colon + 1);
        if (host.find(':') != std::string::npos) throw bad("write an IPv6 address in brackets, e.g. [::1]:14158");
    }
    if (host.empty()) throw bad("no host before the port (e.g. 127.0.0.1:" + (port.empty() ? "14158" : port) + ")");
    if (port.empty()) throw bad("no port after the ':'");
    if (port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos)
        throw bad("the port '" + port + "' is not a number from 1 to 65535");
    const int number = std::stoi(port);
    if (number < 1 || number > 65535) throw bad("the port " + port + " is not in 1..65535");
    return {host, uint16_t(number)};
}

std::vector<SocketAddress> resolve_server_address(const ServerAddress &server) {
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_NUMERICSERV;
    addrinfo *found = nullptr;
    const std::string port = std::to_string(server.port);
    if (const int err = getaddrinfo(server.host.c_str(), port.c_str(), &hints, &found); err != 0)
        throw std::runtime_error("cannot resolve '" + server.host + "': " + gai_strerror(err));
    std::vector<SocketAddress> out;
    for (const addrinfo *a = found; a; a = a->ai_next) {
        if (a->ai_addrlen > sizeof(sockaddr_storage)) continue;
        SocketAddress s;
        std::memcpy(&s.address, a->ai_addr, a->ai_addrlen);
        s.length = a->ai_addrlen;
        s.family = a->ai_family;
        out.push_back(s);
    }
    freeaddrinfo(found);
    if (out.empty()) throw std::runtime_error("cannot resolve '" + server.host + "': no address");
    return out;
}

namespace {

using Clock = std::chrono::steady_clock;

// Waits until fd is ready for `events`, for at most timeout_ms, in short slices so that *stop is seen
// soon. Returns 1 when ready, 0 on a time-out, -1 when stopped (errno set by a failed poll otherwise).
int wait_for(int fd, short events, int timeout_ms, const std::atomic<bool> *stop) {
    const auto deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
    for (;;) {
        if (stop && stop->load()) return -1;
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
        if (left <= 0) return 0;
        pollfd p{fd, events, 0};
        const int r = ::poll(&p, 1, int(std::min<long long>(left, 50)));
        if (r > 0) return 1;
        if (r < 0 && errno != EINTR) return -2;
    }
}

}  // namespace

bool TcpConnection::connect(const std::vector<SocketAddress> &addresses, int timeout_ms, const std::atomic<bool> *stop) {
    close();
    error_ = "no address";
    for (const SocketAddress &a : addresses) {
        // Non-blocking from the start: connect() then returns at once and poll() bounds the wait.
        const int fd = ::socket(a.family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        if (fd < 0) {
            error_ = std::strerror(errno);
            continue;
        }
        int err = 0;
        if (::connect(fd, reinterpret_cast<const sockaddr *>(&a.address), a.length) != 0) {
            err = errno;
            if (err == EINPROGRESS) {
                const int ready = wait_for(fd, POLLOUT, timeout_ms, stop);
                socklen_t len = sizeof(err);
                if (ready == 1) getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
                else err = ready == 0 ? ETIMEDOUT : ready == -1 ? ECANCELED : errno;
            }
        }
        if (err == 0) {
            fd_ = fd;
            error_.clear();
            return true;
        }
        ::close(fd);
        error_ = err == ECANCELED ? "stopped" : std::strerror(err);
        if (err == ECANCELED) break;
    }
    return false;
}

bool TcpConnection::send_all(std::span<const uint8_t> bytes, int stall_timeout_ms, const std::atomic<bool> *stop) {
    if (fd_ < 0) {
        error_ = "not connected";
        return false;
    }
    size_t sent = 0;
    while (sent < bytes.size()) {
        // MSG_NOSIGNAL: a peer that went away gives EPIPE here, not SIGPIPE to the process.
        const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
        if (n > 0) {
            sent += size_t(n);
            continue;
        }
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            const int ready = wait_for(fd_, POLLOUT, stall_timeout_ms, stop);
            if (ready == 1) continue;
            error_ = ready == 0 ? "the peer took nothing for " + std::to_string(stall_timeout_ms / 1000) + " s"
                     : ready == -1 ? "stopped"
                                   : std::strerror(errno);
        } else {
            error_ = std::strerror(errno);
        }
        close();
        return false;
    }
    return true;
}

void TcpConnection::close() {
    if (fd_ < 0) return;
    ::shutdown(fd_, SHUT_WR);  // end of stream after what was sent
    ::close(fd_);
    fd_ = -1;
}

}  // namespace neepp
