// HTTP API for people and SCADA gateways. Handlers only read snapshots and post requests to the
// service loop; they never touch the camera, so a slow client cannot delay a measurement and a
// measurement cannot stall the API.
#include "daemon/http_api.hpp"

#include <httplib.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>

#include "core/common/error.hpp"
#include "daemon/daemon.hpp"
#include "daemon/http_limits.hpp"
#include "daemon/http_token.hpp"
#include "daemon/iso_time.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::daemon {

namespace {

constexpr int kDefaultHistoryLimit = 1000;
constexpr int kMaxHistoryLimit = 100000;

struct Endpoint {
    const char* method;
    const char* path;
    const char* what;
};
// What GET / lists; POSTs need the bearer token and take no body.
constexpr Endpoint kEndpoints[] = {
    {"GET", "/v1/latest", "the latest result, with stale and stale_since"},
    {"GET", "/v1/health", "the service's health; 503 on a fault or a stale result, reasons say why"},
    {"GET", "/v1/history?since=ISO&limit=N", "results since a time (default: the last 24 h)"},
    {"GET", "/v1/images/latest/{left,disparity,thickness}.png", "pictures of the latest measurement"},
    {"POST", "/v1/measure", "measure now (token)"},
    {"POST", "/v1/baseline[?force=1]", "capture a new clean-blade baseline (token)"},
    {"POST", "/v1/baseline/restore", "go back to the previous baseline (token)"},
    {"POST", "/v1/alarm/reset", "reset a latched alarm (token)"},
};

void sendJson(httplib::Response& res, int status, const nlohmann::json& body) {
    res.status = status;
    res.set_content(body.dump(2) + "\n", "application/json");
}

void sendError(httplib::Response& res, int status, const std::string& message) {
    sendJson(res, status, {{"error", message}, {"status", status}});
}

std::string lower(std::string text) {
    for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
}

// The origins a page of this server itself would send; a browser adds Origin to every
// cross-origin request, so any other value is a page elsewhere trying to reach the box.
std::vector<std::string> ownOrigins(const config::HttpConfig& config, int port) {
    const std::string suffix = ":" + std::to_string(port);
    std::vector<std::string> origins{"http://127.0.0.1" + suffix, "http://localhost" + suffix, "http://[::1]" + suffix};
    if (!config::isLoopbackAddress(config.address) && config.address != "0.0.0.0" && config.address != "::") {
        origins.push_back("http://" + lower(config.address) + suffix);
    }
    return origins;
}

// Host names that mean this machine's loopback: anything else in Host on a loopback listener is
// a DNS-rebinding page that made evil.example resolve to 127.0.0.1.
bool loopbackHost(const std::string& host) {
    const std::string h = lower(host.substr(0, host.rfind(':') == std::string::npos || host.back() == ']'
                                                   ? host.size()
                                                   : host.rfind(':')));
    return h == "localhost" || h == "[::1]" || h.rfind("127.", 0) == 0;
}

// HTML forms post these without any preflight; nothing of ours takes them.
bool formContentType(const std::string& contentType) {
    const std::string type = lower(contentType.substr(0, contentType.find(';')));
    for (const char* form : {"application/x-www-form-urlencoded", "multipart/form-data", "text/plain"}) {
        if (type.find(form) != std::string::npos) return true;
    }
    return false;
}

std::string bearerValue(const std::string& header) {
    const std::size_t space = header.find(' ');
    if (space == std::string::npos || lower(header.substr(0, space)) != "bearer") return {};
    const std::size_t start = header.find_first_not_of(' ', space);
    return start == std::string::npos ? std::string() : header.substr(start);
}

std::string client(const httplib::Request& req) {
    const std::string agent = req.get_header_value("User-Agent");
    return "http " + req.remote_addr + (agent.empty() ? "" : " (" + agent.substr(0, 80) + ")");
}

}  // namespace

HttpApi::HttpApi(Daemon& daemon, const config::HttpConfig& config)
    : daemon_(daemon), server_(makeLimitedServer(listenFd_)), config_(config) {
    if (config.port == 0) {
        port_ = server_->bind_to_any_port(config.address);
    } else {
        port_ = server_->bind_to_port(config.address, config.port) ? config.port : -1;
    }
    if (port_ <= 0) {
        throw Error(kExitUnavailable, "http: cannot listen on " + config.address + ":" + std::to_string(config.port) +
                                          " (address in use, or not an address of this machine)");
    }
    raiseBacklog(listenFd_);
    origins_ = ownOrigins(config, port_);
    route();
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

    // A person or a script arriving at the bare address learns what there is.
    s.Get("/", [this](const httplib::Request&, httplib::Response& res) {
        nlohmann::json endpoints = nlohmann::json::array();
        for (const auto& [method, path, what] : kEndpoints) {
            endpoints.push_back({{"method", method}, {"path", path}, {"what", what}});
        }
        sendJson(res, 200, {{"name", "icewatchd"}, {"version", daemon_.version()}, {"endpoints", endpoints}});
    });

    s.Get("/v1/latest", [this](const httplib::Request&, httplib::Response& res) {
        if (const auto latest = daemon_.latest()) {
            sendJson(res, 200, *latest);
        } else {
            sendError(res, 503, "no result yet");
        }
    });

    s.Get("/v1/health", [this](const httplib::Request&, httplib::Response& res) {
        // 503 on a fault, so that a probe that only looks at the status code sees it too.
        const nlohmann::json health = daemon_.health();
        sendJson(res, health["status"] == "fault" ? 503 : 200, health);
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
            sendError(res, 404, "no " + name + " picture yet: no cycle has measured");
        }
    });

    // Every request: a browser page of another origin, or a rebound host name, gets nothing.
    s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
        if (req.headers.size() > kHttpMaxHeaders) {
            sendError(res, 431, "more than " + std::to_string(kHttpMaxHeaders) + " header fields");
            return httplib::Server::HandlerResponse::Handled;
        }
        if (const std::string refusal = refusedOrigin(req); !refusal.empty()) {
            log::get("http")->warn("{} {} from {} refused: {}", req.method, req.path, req.remote_addr, refusal);
            sendError(res, 403, refusal);
            return httplib::Server::HandlerResponse::Handled;
        }
        // Before httplib reads (and for multipart, parses) the body.
        if (req.method == "POST" && formContentType(req.get_header_value("Content-Type"))) {
            sendError(res, 415, "form content types are refused: send no body or application/json");
            return httplib::Server::HandlerResponse::Handled;
        }
        return httplib::Server::HandlerResponse::Unhandled;
    });

    const auto post = [this, &s](const std::string& path, const std::string& what, auto request) {
        s.Post(path, [this, what, request](const httplib::Request& req, httplib::Response& res) {
            if (!authorised(req, res)) return;
            if (!(this->*request)(req, res)) return;
            log::get("http")->info("{} accepted from {}", req.path, client(req));
            sendJson(res, 202, {{"accepted", what}});
        });
        s.Get(path, [path](const httplib::Request&, httplib::Response& res) {
            res.set_header("Allow", "POST");
            sendError(res, 405, path + " takes POST");
        });
    };
    post("/v1/measure", "measure", &HttpApi::measure);
    post("/v1/baseline", "baseline", &HttpApi::baseline);
    post("/v1/baseline/restore", "baseline_restore", &HttpApi::restoreBaseline);
    post("/v1/alarm/reset", "alarm_reset", &HttpApi::resetAlarm);

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

std::string HttpApi::refusedOrigin(const httplib::Request& req) const {
    if (req.has_header("Origin")) {
        const std::string origin = lower(req.get_header_value("Origin"));
        if (std::find(origins_.begin(), origins_.end(), origin) == origins_.end()) {
            return "requests from pages of another origin (" + origin.substr(0, 100) + ") are refused";
        }
    }
    if (config::isLoopbackAddress(config_.address) && req.has_header("Host") &&
        !loopbackHost(req.get_header_value("Host"))) {
        return "Host must name this machine's loopback (127.0.0.1, localhost, [::1])";
    }
    return {};
}

bool HttpApi::authorised(const httplib::Request& req, httplib::Response& res) const {
    const HttpToken token = daemon_.token();
    if (token.value.empty()) {
        log::get("http")->error("{} from {} refused: no token ({})", req.path, client(req), token.problem);
        sendError(res, 503, "no token is configured, so no request may change anything: " + token.problem);
        return false;
    }
    if (!sameToken(bearerValue(req.get_header_value("Authorization")), token.value)) {
        log::get("http")->warn("{} from {} refused: missing or wrong token", req.path, client(req));
        res.set_header("WWW-Authenticate", "Bearer");
        sendError(res, 401, "this request needs the header Authorization: Bearer <token> (http.token or the file "
                            "http.token_file)");
        return false;
    }
    return true;
}

bool HttpApi::measure(const httplib::Request&, httplib::Response&) {
    daemon_.requestMeasure();
    return true;
}

bool HttpApi::baseline(const httplib::Request& req, httplib::Response& res) {
    const bool force = req.has_param("force") && req.get_param_value("force") != "0";
    if (const auto ice = daemon_.iceShown(); ice && !force) {
        sendError(res, 409, "the current result shows ice (" + *ice +
                                "): a baseline now would make that ice the clean reference. Post again with "
                                "?force=1 if the blade is clean.");
        return false;
    }
    daemon_.requestBaseline(client(req) + (force ? ", forced" : ""));
    return true;
}

bool HttpApi::restoreBaseline(const httplib::Request& req, httplib::Response&) {
    daemon_.requestBaselineRestore(client(req));
    return true;
}

bool HttpApi::resetAlarm(const httplib::Request&, httplib::Response&) {
    daemon_.requestAlarmReset();
    return true;
}

}  // namespace icewatch::daemon
