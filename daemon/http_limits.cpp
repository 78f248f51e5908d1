// Resource limits of the HTTP server. cpp-httplib's own defaults (8 workers, backlog 5, no bound
// on the number of header lines) let 40 slow connections block every health probe.
#include "daemon/http_limits.hpp"

#include <sys/socket.h>

#include <httplib.h>

#include "drivers/log/log.hpp"

namespace icewatch::daemon {

void applyLimits(httplib::Server& server, int& listenFd) {
    server.new_task_queue = [] { return new httplib::ThreadPool(kHttpWorkers); };
    server.set_payload_max_length(64 * 1024);
    server.set_read_timeout(3, 0);
    server.set_write_timeout(5, 0);
    server.set_keep_alive_max_count(10);
    server.set_keep_alive_timeout(2);
    server.set_socket_options([&listenFd](int sock) {
        httplib::default_socket_options(sock);
        listenFd = sock;
    });
}

void raiseBacklog(int listenFd) {
    if (listenFd >= 0 && ::listen(listenFd, kHttpBacklog) != 0) {
        log::get("http")->warn("cannot raise the listen backlog to {}", kHttpBacklog);
    }
}

}  // namespace icewatch::daemon
