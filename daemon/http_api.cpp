// HTTP API for people and SCADA gateways. Handlers only read snapshots and post requests to the
// service loop; they never touch the camera, so a slow client cannot delay a measurement and a
// measurement cannot stall the API.
#include "daemon/http_api.hpp"

#include <httplib.h>

#include <chrono>
#include <charconv>

#include "core/common/error.hpp"
#include "daemon/daemon.hpp"
#include "daemon/iso_time.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::daemon {

namespace {

constexpr int kDefaultHistoryLimit = 1000;
constexpr int kMaxHistoryLimit = 100000;

void sendJson(httplib::Response& res, int status, const nlohmann::json& body) {
    res.status = status;
    res.set_content(body.dump(2) + "\n", "application/json");
}

void sendError(httplib::Response& res, int status, const std::string& message) {
    sendJson(res, status, {{"error", message}, {"status", status}});
}

// Constant-time comparison: the token must not leak through response timing.
bool sameToken(const std::string& a, const std::string& b) {
    unsigned char diff = a.size() == b.size() ? 0 : 1;
    for (std::size_t i = 0; i < a.size(); ++i) {
        diff |= static_cast<unsigned char>(a[i] ^ (i < b.size() ? b[i] : 0));
    }
    return diff == 0;
}

}  // namespace

HttpApi::HttpApi(Daemon& daemon, const config::HttpConfig& config)
    : daemon_(daemon), server_(std::make_unique<httplib::Server>()) {
    route();
    server_->set_payload_max_length(64 * 1024);
    server_->set_read_timeout(5, 0);
    server_->set_write_timeout(5, 0);
    if (config.port == 0) {
        port_ = server_->bind_to_any_port(config.address);
    } else {
        port_ = server_->bind_to_port(config.address, config.port) ? config.port : -1;
    }
    if (port_ <= 0) {
        throw Error(kExitUnavailable, "http: cannot listen on " + config.address + ":" + std::to_string(config.port) +
                                          " (address in use, or not an address of this machine)");
    }
    thread_ = std::thread([this] { server_->listen_after_bind(); });
    log::get("http")->info("listening on {}:{}", config.address, port_);
}

HttpApi::~HttpApi() {
    server_->stop();
    if (thread_.joinable()) {
        thread_.join();
    }
}

void HttpApi::route() {
    httplib::Server& s = *server_;

    s.Get("/v1/latest", [this](const httplib::Request&, httplib::Response& res) {
        if (const auto latest = daemon_.latest()) {
            sendJson(res, 200, *latest);
        } else {
            sendError(res, 503, "no result yet");
        }
    });

    s.Get("/v1/health", [this](const httplib::Request&, httplib::Response& res) {
        sendJson(res, 200, daemon_.health());
    });

    s.Get("/v1/history", [this](const httplib::Request& req, httplib::Response& res) {
        auto since = daemon_.now() - std::chrono::hours(24);
        if (req.has_param("since")) {
            const auto parsed = parseIsoUtc(req.get_param_value("since"));
            if (!parsed) {
                sendError(res, 400, "since: not an ISO 8601 time (e.g. 2026-01-31T12:00:00Z)");
                return;
            }
            since = *parsed;
        }
        int limit = kDefaultHistoryLimit;
        if (req.has_param("limit")) {
            const std::string text = req.get_param_value("limit");
            const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), limit);
            if (ec != std::errc() || end != text.data() + text.size() || limit < 1 || limit > kMaxHistoryLimit) {
                sendError(res, 400, "limit: must be an integer from 1 to " + std::to_string(kMaxHistoryLimit));
                return;
            }
        }
        sendJson(res, 200, daemon_.history(since, limit));
    });

    s.Get(R"(/v1/images/latest/([a-z]+)\.png)", [this](const httplib::Request& req, httplib::Response& res) {
        const std::string name = req.matches[1];
        if (name != "left" && name != "disparity" && name != "thickness") {
            sendError(res, 404, "no picture named " + name + " (left, disparity, thickness)");
            return;
        }
        if (const auto png = daemon_.picture(name)) {
            res.set_content(*png, "image/png");
        } else {
            sendError(res, 404, "no " + name + " picture yet: no cycle has measured a volume");
        }
    });

    const auto post = [this, &s](const std::string& path, const std::string& what, auto request) {
        s.Post(path, [this, what, request](const httplib::Request& req, httplib::Response& res) {
            const std::string token = daemon_.token();
            if (!token.empty()) {
                const std::string header = req.get_header_value("Authorization");
                const std::string prefix = "Bearer ";
                if (header.rfind(prefix, 0) != 0 || !sameToken(header.substr(prefix.size()), token)) {
                    res.set_header("WWW-Authenticate", "Bearer");
                    sendError(res, 401, "this request needs the header Authorization: Bearer <http.token>");
                    return;
                }
            }
            (daemon_.*request)();
            sendJson(res, 202, {{"accepted", what}});
        });
        s.Get(path, [path](const httplib::Request&, httplib::Response& res) {
            res.set_header("Allow", "POST");
            sendError(res, 405, path + " takes POST");
        });
    };
    post("/v1/measure", "measure", &Daemon::requestMeasure);
    post("/v1/baseline", "baseline", &Daemon::requestBaseline);
    post("/v1/alarm/reset", "alarm_reset", &Daemon::requestAlarmReset);

    // Anything else that ends in an error without a body of ours (unknown path, wrong method,
    // a request httplib could not parse) still answers JSON.
    s.set_error_handler(httplib::Server::HandlerWithResponse([](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty()) {
            return httplib::Server::HandlerResponse::Unhandled;
        }
        const std::string what = res.status == 404 ? "no such resource: " + req.method + " " + req.path
                                                   : "request refused with HTTP status " + std::to_string(res.status);
        sendError(res, res.status, what);
        return httplib::Server::HandlerResponse::Handled;
    }));
    s.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "unknown error";
        try {
            std::rethrow_exception(ep);
        } catch (const std::exception& e) {
            what = e.what();
        } catch (...) {
        }
        log::get("http")->error("{} {}: {}", req.method, req.path, what);
        sendError(res, 500, "internal error: " + what);
    });
}

}  // namespace icewatch::daemon
