#include "daemon/http_api.hpp"

#include <arpa/inet.h>
#include <algorithm>
#include <poll.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <httplib.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/daemon/rig.hpp"

namespace icewatch::daemon::test {
namespace {

struct Api {
    explicit Api(const std::function<void(config::Config&)>& adjust = {})
        : rig(adjust), http(*rig.daemon, rig.config.http), client("127.0.0.1", http.port()) {}
    Rig rig;
    HttpApi http;
    httplib::Client client;
};

nlohmann::json body(const httplib::Result& r) {
    return nlohmann::json::parse(r->body, nullptr, false);
}

// A TCP connection to the API on loopback, or -1.
int connectTo(int port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        ::close(fd);
        return -1;
    }
    return fd;
}

// Sends raw bytes and returns the first line of the answer.
std::string rawExchange(int port, const std::string& request) {
    const int fd = connectTo(port);
    if (fd < 0) return "connect failed";
    (void)!::write(fd, request.data(), request.size());
    ::shutdown(fd, SHUT_WR);
    std::string answer;
    char buffer[4096];
    ssize_t n = 0;
    while ((n = ::read(fd, buffer, sizeof buffer)) > 0) answer.append(buffer, static_cast<std::size_t>(n));
    ::close(fd);
    return answer.substr(0, answer.find("\r\n"));
}

TEST(HttpApi, LatestBeforeAndAfterTheFirstResult) {
    Api api;
    auto r = api.client.Get("/v1/latest");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 503);
    EXPECT_EQ(body(r)["error"], "no result yet");

    api.rig.daemon->runOnce();
    r = api.client.Get("/v1/latest");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/json");
    const auto doc = body(r);
    EXPECT_EQ(doc["status"], "ok");
    EXPECT_EQ(doc["volume_mm3"], 1000.0);
    EXPECT_EQ(doc["stale"], false);
    EXPECT_EQ(doc["time"], api.rig.latestFile()["time"]);
}

TEST(HttpApi, HistoryWithSinceAndLimit) {
    Api api;
    api.rig.daemon->runUntil(api.rig.at(3 * 600 + 1));
    auto r = api.client.Get("/v1/history?since=2026-01-01T00:10:00Z");
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200);
    auto rows = body(r);
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0]["time"], "2026-01-01T00:10:00Z");
    r = api.client.Get("/v1/history?since=2026-01-01&limit=2");
    ASSERT_TRUE(r);
    EXPECT_EQ(body(r).size(), 2u);
    r = api.client.Get("/v1/history");  // default: the last 24 h
    ASSERT_TRUE(r);
    EXPECT_EQ(body(r).size(), 4u);
}

TEST(HttpApi, MalformedRequestsGetJsonErrors) {
    Api api;
    const std::vector<std::pair<std::string, int>> cases{
        {"/v1/history?since=yesterday", 400},
        {"/v1/history?since=2026-02-30T00:00:00Z", 400},
        {"/v1/history?since=2026-01-01T25:00:00Z", 400},
        {"/v1/history?limit=0", 400},
        {"/v1/history?limit=12abc", 400},
        {"/v1/history?limit=99999999999999999999", 400},
        {"/v1/nothing", 404},
        {"/v1/images/latest/left.png", 404},  // no cycle yet
        {"/v1/images/latest/secret.png", 404},
        {"/v1/images/latest/../../etc/passwd", 404},
        {"/v1/measure", 405},
    };
    for (const auto& [path, status] : cases) {
        auto r = api.client.Get(path.c_str());
        ASSERT_TRUE(r) << path;
        EXPECT_EQ(r->status, status) << path;
        const auto doc = body(r);
        EXPECT_TRUE(doc.is_object() && doc["error"].is_string()) << path << ": " << r->body;
    }
    auto r = api.client.Delete("/v1/latest");
    ASSERT_TRUE(r);
    EXPECT_GE(r->status, 400);
    EXPECT_LT(r->status, 500);
    EXPECT_TRUE(body(r)["error"].is_string()) << r->body;
    // Not HTTP at all, and a request line far too long: refused, and the server carries on.
    // Each is answered with a 4xx or dropped (closed): never a 2xx, never a crash.
    const std::string garbage = rawExchange(api.http.port(), "\x01\x02garbage\r\n\r\n");
    EXPECT_TRUE(garbage.empty() || garbage.find(" 400 ") != std::string::npos) << garbage;
    const std::string longLine = rawExchange(api.http.port(), "GET /" + std::string(20000, 'a') + " HTTP/1.1\r\n\r\n");
    EXPECT_TRUE(longLine.empty() || longLine.find(" 4") != std::string::npos) << longLine;
    r = api.client.Get("/v1/health");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 503) << "no result yet: a fault";
    EXPECT_EQ(body(r)["alarm"], "fault");
}

TEST(HttpApi, PostsAreQueuedForTheLoopAndNeedTheToken) {
    Api api([](config::Config& c) { c.http.token = "s3cret"; });
    api.rig.daemon->runUntil(api.rig.at(1));
    auto r = api.client.Post("/v1/measure");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 401);
    EXPECT_TRUE(body(r)["error"].is_string());
    r = api.client.Post("/v1/measure", httplib::Headers{{"Authorization", "Bearer wrong"}}, "", "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 401);
    EXPECT_EQ(api.rig.daemon->history(testEpoch(), 10).size(), 1u);

    r = api.client.Post("/v1/measure", httplib::Headers{{"Authorization", "Bearer s3cret"}}, "", "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 202);
    EXPECT_EQ(body(r)["accepted"], "measure");
    api.rig.daemon->runUntil(api.rig.at(2));
    EXPECT_EQ(api.rig.daemon->history(testEpoch(), 10).size(), 2u) << "the request ran a cycle";
}

std::string tokenOf(const Api& api) {
    std::string token;
    std::getline(std::ifstream(api.rig.dir / "http-token"), token);
    return token;
}

httplib::Headers bearer(const std::string& token) {
    return {{"Authorization", "Bearer " + token}};
}

TEST(HttpApi, EveryPostNeedsATokenEvenWhenNoneIsConfigured) {
    Api api;  // http.token empty: the daemon made http.token_file
    const std::string token = tokenOf(api);
    ASSERT_EQ(token.size(), 64u);
    EXPECT_EQ(std::filesystem::status(api.rig.dir / "http-token").permissions() & std::filesystem::perms::all,
              std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                  std::filesystem::perms::group_read);
    for (const char* path : {"/v1/measure", "/v1/baseline?force=1", "/v1/baseline/restore", "/v1/alarm/reset"}) {
        auto r = api.client.Post(path);
        ASSERT_TRUE(r) << path;
        EXPECT_EQ(r->status, 401) << path;
        EXPECT_EQ(r->get_header_value("WWW-Authenticate"), "Bearer") << path;
        std::string wrong = token;
        wrong.back() = wrong.back() == '0' ? '1' : '0';
        r = api.client.Post(path, bearer(wrong), "", "application/json");
        ASSERT_TRUE(r) << path;
        EXPECT_EQ(r->status, 401) << path;
    }
    // The scheme is case-insensitive (RFC 7235); the token is not.
    auto r = api.client.Post("/v1/measure", httplib::Headers{{"Authorization", "bEaReR " + token}}, "", "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 202);
}

TEST(HttpApi, CrossOriginAndFormRequestsAreRefusedWhateverTheyCarry) {
    Api api;
    const std::string token = tokenOf(api);
    const std::string own = "http://127.0.0.1:" + std::to_string(api.http.port());
    // What a page on another site submits with a plain HTML form: refused before anything else.
    auto r = api.client.Post("/v1/baseline", httplib::Headers{{"Origin", "http://evil.example"}}, "x=1",
                             "application/x-www-form-urlencoded");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 403);
    EXPECT_NE(body(r)["error"].get<std::string>().find("another origin"), std::string::npos) << r->body;
    httplib::Headers foreign = bearer(token);
    foreign.emplace("Origin", "null");
    r = api.client.Post("/v1/measure", foreign, "", "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 403) << "even with the token";
    r = api.client.Get("/v1/latest", httplib::Headers{{"Origin", "http://evil.example"}});
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 403) << "reads too";
    // DNS rebinding: the page's own origin, but a host name that is not this loopback.
    r = api.client.Get("/v1/latest", httplib::Headers{{"Host", "evil.example:" + std::to_string(api.http.port())}});
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 403);
    for (const char* type : {"application/x-www-form-urlencoded", "multipart/form-data; boundary=x", "text/plain"}) {
        r = api.client.Post("/v1/measure", bearer(token), "", type);
        ASSERT_TRUE(r) << type;
        EXPECT_EQ(r->status, 415) << type;
    }
    httplib::Headers same = bearer(token);
    same.emplace("Origin", own);
    r = api.client.Post("/v1/measure", same, "", "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 202) << "this server's own origin with the token";
}

TEST(HttpApi, ABaselineWhileTheResultShowsIceNeedsForce) {
    Api api;
    const std::string token = tokenOf(api);
    api.rig.daemon->runOnce();  // the scripted chain measures 1000 mm³: alarm level
    ASSERT_EQ(api.rig.latestFile()["alarm"], "alarm");
    auto r = api.client.Post("/v1/baseline", bearer(token), "", "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 409);
    EXPECT_NE(body(r)["error"].get<std::string>().find("shows ice (alarm level alarm)"), std::string::npos) << r->body;
    api.rig.daemon->runUntil(api.rig.at(1));
    EXPECT_TRUE(api.rig.daemon->health()["last_baseline_capture"].is_null()) << "nothing was captured";
    r = api.client.Post("/v1/baseline?force=1", bearer(token), "", "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 202);
    api.rig.daemon->runUntil(api.rig.at(2));
    const auto capture = api.rig.daemon->health()["last_baseline_capture"];
    EXPECT_TRUE(capture["ok"].get<bool>()) << capture;
    EXPECT_NE(capture["requested_by"].get<std::string>().find("http 127.0.0.1"), std::string::npos) << capture;
}

TEST(HttpApi, FortySlowClientsDoNotBlockTheHealthProbe) {
    Api api;
    api.rig.daemon->runOnce();
    // Each holds a worker with a request it never finishes.
    std::vector<int> slow;
    for (int i = 0; i < 40; ++i) {
        const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in addr{};
        addr.sin_family = AF_INET;
        addr.sin_port = htons(static_cast<uint16_t>(api.http.port()));
        addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
        const std::string start = "GET /v1/health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ";
        ASSERT_EQ(::write(fd, start.data(), start.size()), static_cast<ssize_t>(start.size()));
        slow.push_back(fd);
    }
    auto r = api.client.Get("/v1/health");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
    // Answered while they all still hold their connection: the server has closed none of them
    // (with too few workers the probe is served only after it times the slow ones out).
    std::vector<pollfd> fds;
    for (int fd : slow) fds.push_back({fd, POLLIN, 0});
    EXPECT_EQ(::poll(fds.data(), fds.size(), 0), 0) << "a slow connection was closed before the probe was answered";
    for (int fd : slow) ::close(fd);
}

TEST(HttpApi, AHeaderFloodIsRefused) {
    Api api;
    api.rig.daemon->runOnce();
    std::string flood = "GET /v1/health HTTP/1.1\r\nHost: 127.0.0.1\r\n";
    for (int i = 0; i < 2000; ++i) flood += "X-Flood-" + std::to_string(i) + ": " + std::string(100, 'a') + "\r\n";
    flood += "\r\n";
    const std::string answer = rawExchange(api.http.port(), flood);
    EXPECT_TRUE(answer.empty() || answer.find(" 431 ") != std::string::npos || answer.find(" 400 ") != std::string::npos)
        << answer;
    auto r = api.client.Get("/v1/health");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
}

TEST(HttpApi, PicturesOfTheLastCycle) {
    Api api;
    api.rig.daemon->runOnce();
    for (const char* name : {"left", "disparity", "thickness"}) {
        auto r = api.client.Get((std::string("/v1/images/latest/") + name + ".png").c_str());
        ASSERT_TRUE(r) << name;
        EXPECT_EQ(r->status, 200) << name;
        EXPECT_EQ(r->get_header_value("Content-Type"), "image/png");
        EXPECT_EQ(r->body.substr(1, 3), "PNG") << name;
    }
}

TEST(HttpApi, PicturesOfARefusedCycle) {
    // A refused cycle is when a person wants to look: its pictures are served, not a 404.
    Api api;
    api.rig.chain->script = [](int, const StereoPair& pair) {
        ChainResult r = refusedResult("too few valid disparities");
        r.pictures.left = cv::Mat(pair.left.size(), CV_8UC3, cv::Scalar(10, 20, 30));
        r.pictures.disparity = cv::Mat(pair.left.size(), CV_8UC3, cv::Scalar(40, 50, 60));
        r.pictures.thickness = cv::Mat(pair.left.size(), CV_8UC3, cv::Scalar(70, 80, 90));
        return r;
    };
    api.rig.daemon->runOnce();
    ASSERT_EQ((*api.rig.daemon->latest())["status"], "refused");
    auto r = api.client.Get("/v1/images/latest/disparity.png");
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200);
    const std::vector<uchar> bytes(r->body.begin(), r->body.end());
    const cv::Mat served = cv::imdecode(bytes, cv::IMREAD_COLOR);
    ASSERT_FALSE(served.empty());
    EXPECT_EQ(served.at<cv::Vec3b>(0, 0), cv::Vec3b(40, 50, 60));
}

// Sends raw bytes, keeps the connection open as curl does, and returns the status line of the
// answer ("" when none came within the guard).
std::string rawRequestKeptOpen(int port, const std::string& request) {
    const int fd = connectTo(port);
    std::string answer;
    if (fd >= 0) {
        (void)!::write(fd, request.data(), request.size());
        pollfd p{fd, POLLIN, 0};
        char buffer[4096];
        ssize_t n = 0;
        while (answer.find("\r\n") == std::string::npos && ::poll(&p, 1, 30000) == 1 &&
               (n = ::read(fd, buffer, sizeof buffer)) > 0) {
            answer.append(buffer, static_cast<std::size_t>(n));
        }
        ::close(fd);
    }
    return answer.substr(0, answer.find("\r\n"));
}

TEST(HttpApi, APostWithoutABodyOrContentLengthIsAccepted) {
    Api api([](config::Config& c) { c.http.token = "s3cret"; });
    // What `curl -X POST -H "Authorization: Bearer ..." .../v1/measure` sends: no Content-Length,
    // and the connection stays open for the answer.
    const std::string status = rawRequestKeptOpen(
        api.http.port(), "POST /v1/measure HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer s3cret\r\n"
                         "User-Agent: curl/7.88.1\r\nAccept: */*\r\n\r\n");
    EXPECT_EQ(status, "HTTP/1.1 202 Accepted");
    // An announced body is still read as before.
    auto r = api.client.Post("/v1/alarm/reset", httplib::Headers{{"Authorization", "Bearer s3cret"}}, "{}",
                             "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 202);
}

TEST(HttpApi, TheRootListsTheEndpointsAndTheVersion) {
    Api api;
    auto r = api.client.Get("/");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/json");
    const auto doc = body(r);
    EXPECT_EQ(doc["version"], "test-version");
    std::vector<std::string> paths;
    for (const auto& e : doc["endpoints"]) paths.push_back(e["method"].get<std::string>() + " " + e["path"].get<std::string>());
    for (const char* expected : {"GET /v1/latest", "GET /v1/health", "POST /v1/measure", "POST /v1/alarm/reset"}) {
        EXPECT_NE(std::find(paths.begin(), paths.end(), expected), paths.end()) << expected;
    }
}

TEST(HttpApi, HealthIs503WhileTheResultIsStaleAndSaysSince) {
    Api api;
    api.rig.daemon->runOnce();
    auto r = api.client.Get("/v1/health");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
    EXPECT_EQ(body(r)["reasons"], nlohmann::json::array());
    api.rig.clock.advance(std::chrono::seconds(1201));  // no cycle ran: the loop is not running
    r = api.client.Get("/v1/health");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 503);
    const auto health = body(r);
    EXPECT_EQ(health["alarm"], "alarm") << "the level itself is not fault: staleness alone is enough";
    EXPECT_EQ(health["reasons"][0], "stale since 2026-01-01T00:20:00Z (latest ok result 2026-01-01T00:00:00Z)")
        << health["reasons"];
}

TEST(HttpApi, HealthSaysWhatIsWrong) {
    Api api;
    api.rig.source->plugged = false;
    api.rig.daemon->runOnce();
    auto r = api.client.Get("/v1/health");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 503) << "a probe that reads only the status code sees the fault";
    const auto health = body(r);
    EXPECT_EQ(health["status"], "fault");
    EXPECT_EQ(health["camera"], "offline");
    EXPECT_EQ(health["alarm"], "fault");
    EXPECT_NE(health["reasons"].dump().find("camera offline"), std::string::npos) << health["reasons"];
    EXPECT_EQ(health["version"], "test-version");
}

}  // namespace
}  // namespace icewatch::daemon::test
