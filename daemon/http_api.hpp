#pragma once

#include <memory>
#include <string>
#include <thread>

#include "core/config/config.hpp"

namespace httplib {
class Server;
}

namespace icewatch::daemon {

class Daemon;

// The HTTP API (cpp-httplib), JSON everywhere, errors included:
//   GET  /v1/latest                      the last result, with "stale"
//   GET  /v1/history?since=ISO&limit=N   results since (default: the last 24 h), oldest first
//   GET  /v1/health                      service, camera, alarm, baseline, configuration
//   GET  /v1/images/latest/{left,disparity,thickness}.png
//   POST /v1/measure, /v1/baseline, /v1/alarm/reset   queued for the service loop: 202
// POSTs need "Authorization: Bearer TOKEN" when http.token is set. Malformed requests get a 4xx
// with {"error": "..."}; nothing a client sends can stop the server.
class HttpApi {
public:
    // Binds to config.address:config.port (0: any free port) and serves on its own threads.
    // Throws Error(kExitUnavailable) when it cannot bind.
    HttpApi(Daemon& daemon, const config::HttpConfig& config);
    // Stops serving and joins.
    ~HttpApi();
    HttpApi(const HttpApi&) = delete;
    HttpApi& operator=(const HttpApi&) = delete;

    int port() const { return port_; }

private:
    void route();

    Daemon& daemon_;
    std::unique_ptr<httplib::Server> server_;
    int port_ = 0;
    std::thread thread_;
};

}  // namespace icewatch::daemon
