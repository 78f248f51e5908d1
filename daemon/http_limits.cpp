// Resource limits of the HTTP server. Debian's cpp-httplib (0.11, a compiled library, so its
// compile-time limits cannot be changed here) reads every header line of a request into memory
// with no bound on their number: one request with 257 MiB of headers grew the daemon by 650 MiB
// for good. Its per-read timeout restarts with every byte, so a client trickling one byte a
// second holds a worker for ever, and 8 such clients blocked every health probe. The server below
// reads each connection through a stream that enforces the limits itself.
#include "daemon/http_limits.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstring>
#include <string_view>

#include <httplib.h>

#include "drivers/log/log.hpp"

namespace icewatch::daemon {

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kIoTimeoutMs = 3000;

std::string addressOf(const sockaddr_storage& addr, int& port) {
    char text[INET6_ADDRSTRLEN] = {};
    if (addr.ss_family == AF_INET) {
        const auto& in = reinterpret_cast<const sockaddr_in&>(addr);
        ::inet_ntop(AF_INET, &in.sin_addr, text, sizeof text);
        port = ntohs(in.sin_port);
    } else if (addr.ss_family == AF_INET6) {
        const auto& in6 = reinterpret_cast<const sockaddr_in6&>(addr);
        ::inet_ntop(AF_INET6, &in6.sin6_addr, text, sizeof text);
        port = ntohs(in6.sin6_port);
    }
    return text;
}

// One connection, one request: the head may not exceed kHttpMaxHeadBytes, and reading stops at
// the deadline however the bytes arrive.
class LimitedStream final : public httplib::Stream {
public:
    explicit LimitedStream(int fd)
        : fd_(fd), deadline_(Clock::now() + std::chrono::seconds(kHttpRequestDeadlineS)) {}

    bool is_readable() const override { return wait(POLLIN); }
    bool is_writable() const override { return wait(POLLOUT); }

    ssize_t read(char* ptr, std::size_t size) override {
        // RFC 9112 6.3: a request with neither Content-Length nor Transfer-Encoding has no body.
        // httplib would otherwise read one until the client closes, which `curl -X POST` never
        // does: it waited out the deadline and answered 400.
        if (headDone_ && !bodyAnnounced_) return 0;
        if (!headDone_) {
            if (headBytes_ >= kHttpMaxHeadBytes) return -1;
            size = std::min(size, kHttpMaxHeadBytes - headBytes_);
        }
        if (!wait(POLLIN)) return -1;
        const ssize_t n = ::recv(fd_, ptr, size, 0);
        if (n > 0 && !headDone_) noteHead(std::string_view(ptr, static_cast<std::size_t>(n)));
        return n;
    }

    ssize_t write(const char* ptr, std::size_t size) override {
        if (!waitFor(POLLOUT, kIoTimeoutMs)) return -1;
        return ::send(fd_, ptr, size, MSG_NOSIGNAL);
    }

    void get_remote_ip_and_port(std::string& ip, int& port) const override {
        sockaddr_storage addr{};
        socklen_t length = sizeof addr;
        if (::getpeername(fd_, reinterpret_cast<sockaddr*>(&addr), &length) == 0) ip = addressOf(addr, port);
    }
    void get_local_ip_and_port(std::string& ip, int& port) const override {
        sockaddr_storage addr{};
        socklen_t length = sizeof addr;
        if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &length) == 0) ip = addressOf(addr, port);
    }
    socket_t socket() const override { return fd_; }

private:
    // Reads wait at most until the request's deadline; writes get their own timeout.
    bool wait(short events) const {
        if (events == POLLOUT) return waitFor(POLLOUT, kIoTimeoutMs);
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline_ - Clock::now()).count();
        return left > 0 && waitFor(events, static_cast<int>(std::min<long long>(left, kIoTimeoutMs)));
    }
    bool waitFor(short events, int timeoutMs) const {
        pollfd p{fd_, events, 0};
        int ret = 0;
        while ((ret = ::poll(&p, 1, timeoutMs)) < 0 && errno == EINTR) {
        }
        return ret == 1 && (p.revents & events) != 0;
    }
    // The head ends at the first empty line; what follows is the body, which httplib bounds.
    void noteHead(std::string_view bytes) {
        for (char c : bytes) {
            ++headBytes_;
            head_ += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
            tail_ = (tail_ << 8) | static_cast<unsigned char>(c);
            if ((tail_ & 0xffffffffu) == 0x0d0a0d0au) {
                headDone_ = true;
                bodyAnnounced_ = head_.find("\ncontent-length:") != std::string::npos ||
                                 head_.find("\ntransfer-encoding:") != std::string::npos;
                return;  // a read that ran past the head holds body bytes: not head bytes
            }
        }
    }

    int fd_;
    Clock::time_point deadline_;
    std::size_t headBytes_ = 0;
    bool headDone_ = false;
    bool bodyAnnounced_ = false;
    std::string head_;  // lower case; at most kHttpMaxHeadBytes
    std::uint32_t tail_ = 0;
};

class LimitedServer final : public httplib::Server {
private:
    bool process_and_close_socket(socket_t sock) override {
        LimitedStream stream(sock);
        bool closed = false;
        const bool ok = process_request(stream, /*close_connection=*/true, closed, nullptr);
        ::shutdown(sock, SHUT_RDWR);
        ::close(sock);
        return ok;
    }
};

}  // namespace

std::unique_ptr<httplib::Server> makeLimitedServer(int& listenFd) {
    auto server = std::make_unique<LimitedServer>();
    server->new_task_queue = [] { return new httplib::ThreadPool(kHttpWorkers); };
    server->set_payload_max_length(64 * 1024);
    server->set_socket_options([&listenFd](socket_t sock) {
        httplib::default_socket_options(sock);
        listenFd = sock;
    });
    return server;
}

void raiseBacklog(int listenFd) {
    if (listenFd >= 0 && ::listen(listenFd, kHttpBacklog) != 0) {
        log::get("http")->warn("cannot raise the listen backlog to {}", kHttpBacklog);
    }
}

}  // namespace icewatch::daemon
