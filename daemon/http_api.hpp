#pragma once

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/config/config.hpp"

namespace httplib {
class Server;
struct Request;
struct Response;
}

namespace icewatch::daemon {

class Daemon;

// The HTTP API (cpp-httplib), JSON everywhere, errors included:
//   GET  /v1/latest                      the last result, with "stale"
//   GET  /v1/history?since=ISO&limit=N   results since (default: the last 24 h), oldest first
//   GET  /v1/health                      service, camera, alarm, baseline, configuration
//   GET  /v1/images/latest/{left,disparity,thickness}.png
//   POST /v1/measure, /v1/baseline[?force=1], /v1/baseline/restore, /v1/alarm/reset
//                                        queued for the service loop: 202
// Every POST needs "Authorization: Bearer TOKEN" (http_token.hpp) and no form content type; a
// request with an Origin other than this server's own is refused (403), and so is, on a loopback
// address, a Host that is not loopback (DNS rebinding). A baseline while the current result shows
// ice needs force=1 (409 otherwise). Malformed requests get a 4xx with {"error": "..."}; nothing a
// client sends can stop the server (http_limits.hpp bounds what it may hold).
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
    // Empty when the request may proceed, else why not.
    std::string refusedOrigin(const httplib::Request& req) const;
    // Answers 401/503 itself and returns false when the POST may not proceed.
    bool authorised(const httplib::Request& req, httplib::Response& res) const;
    // The POST actions; false when they answered an error themselves.
    bool measure(const httplib::Request& req, httplib::Response& res);
    bool baseline(const httplib::Request& req, httplib::Response& res);
    bool restoreBaseline(const httplib::Request& req, httplib::Response& res);
    bool resetAlarm(const httplib::Request& req, httplib::Response& res);

    Daemon& daemon_;
    std::unique_ptr<httplib::Server> server_;
    config::HttpConfig config_;
    std::vector<std::string> origins_;
    int listenFd_ = -1;
    int port_ = 0;
    std::thread thread_;
};

}  // namespace icewatch::daemon
