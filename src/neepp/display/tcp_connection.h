// A TCP client over POSIX sockets, made for a render that must never wait on its peer: connecting and
// sending take a time-out and a flag that stops them at once, and a peer that goes away is an error
// returned, never a signal (SIGPIPE) that would end the process.
#pragma once
#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <vector>
#include <sys/socket.h>

namespace neepp {

// HOST:PORT, as a user writes it.
struct ServerAddress {
    std::string host;
    uint16_t port = 0;
    std::string text() const;  // back as HOST:PORT (an IPv6 host in brackets)
};

// Parses HOST:PORT: a name or an IPv4 address and a port in 1..65535, or an IPv6 address in brackets
// ([::1]:14158). Throws std::invalid_argument saying what is wrong (no port, a port out of range, ...).
ServerAddress parse_server_address(const std::string &text);

// One address a host name resolved to.
struct SocketAddress {
    sockaddr_storage address{};
    socklen_t length = 0;
    int family = 0;
};

// The addresses of a server (getaddrinfo). Throws std::runtime_error when the name does not resolve.
// Resolved once, up front: getaddrinfo can wait on a name server for seconds and cannot be interrupted.
std::vector<SocketAddress> resolve_server_address(const ServerAddress &server);

class TcpConnection {
public:
    TcpConnection() = default;
    ~TcpConnection() { close(); }
    TcpConnection(const TcpConnection &) = delete;
    TcpConnection &operator=(const TcpConnection &) = delete;

    // Connects to the first address that accepts within timeout_ms (each). False, with error() saying
    // why, when none does or when *stop becomes true.
    bool connect(const std::vector<SocketAddress> &addresses, int timeout_ms, const std::atomic<bool> *stop = nullptr);
    // Sends every byte. False (and the connection closed) when the peer has taken nothing for
    // stall_timeout_ms, when *stop becomes true, or when the connection broke; error() says which.
    bool send_all(std::span<const uint8_t> bytes, int stall_timeout_ms, const std::atomic<bool> *stop = nullptr);
    bool connected() const { return fd_ >= 0; }
    // Closes the connection after what was sent (the kernel still delivers it).
    void close();
    const std::string &error() const { return error_; }

private:
    int fd_ = -1;
    std::string error_;
};

}  // namespace neepp
