#pragma once

#include <memory>

namespace httplib {
class Server;
}

namespace icewatch::daemon {

// What one client may hold of the HTTP server: workers beyond any realistic number of local
// clients (SCADA gateway, status probes, a person), a request head of at most kHttpMaxHeadBytes
// and kHttpMaxHeaders fields, kHttpRequestDeadlineS for a whole request however slowly its bytes
// trickle in, one request per connection, a small body limit.
constexpr int kHttpWorkers = 64;
constexpr int kHttpBacklog = 128;
constexpr int kHttpMaxHeaders = 64;
constexpr std::size_t kHttpMaxHeadBytes = 16 * 1024;
constexpr int kHttpRequestDeadlineS = 10;

// A cpp-httplib server with those limits. listenFd receives the listening socket for raiseBacklog.
std::unique_ptr<httplib::Server> makeLimitedServer(int& listenFd);

// cpp-httplib listens with a backlog of 5 (compiled in): a burst of connections then waits for
// SYN retries of a second or more, health probes included. listen(2) again sets a larger one.
void raiseBacklog(int listenFd);

}  // namespace icewatch::daemon
