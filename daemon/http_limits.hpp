#pragma once

namespace httplib {
class Server;
}

namespace icewatch::daemon {

// What one client may hold of the HTTP server: workers beyond any realistic number of local
// clients (SCADA gateway, status probes, a person), short read and keep-alive timeouts, a small
// body limit. listenFd receives the listening socket for raiseBacklog.
constexpr int kHttpWorkers = 64;
constexpr int kHttpBacklog = 128;
constexpr int kHttpMaxHeaders = 64;
void applyLimits(httplib::Server& server, int& listenFd);

// cpp-httplib listens with a backlog of 5 (compiled in): a burst of connections then waits for
// SYN retries of a second or more, health probes included. listen(2) again sets a larger one.
void raiseBacklog(int listenFd);

}  // namespace icewatch::daemon
