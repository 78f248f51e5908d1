// icewatchd as a process: readiness over a real NOTIFY_SOCKET, SIGHUP with an invalid config,
// SIGTERM, --once and a bad configuration. Waits are for events (a datagram, an exit, an answer),
// with generous guards against a hang; no assertion depends on how fast anything is.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <cstring>
#include <thread>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "core/calib/stereo_calibration.hpp"
#include "drivers/gpio/fake_output_line.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

extern char** environ;

namespace icewatch::daemon::test {
namespace {

// A guard against a hang, not a timing: nothing waits it out unless something is wrong. A sanitizer
// build on a machine busy with benchmarks took more than 30 s to its first READY.
constexpr int kGuardMs = 120000;

// A nominal calibration of the demo recording's mode, and the demo recording through the fake camera.
std::string configText(const std::filesystem::path& dir, const std::string& interval = "600") {
    const auto calibration = dir / "calibration.yaml";
    if (!std::filesystem::exists(calibration)) {
        calib::saveCalibration(calibration, calib::nominalCalibration({1280, 720}, 80.0, 60.0));
    }
    return R"({"daemon": {"interval_s": )" + interval + R"(, "state_dir": ")" + (dir / "state").string() +
           R"("}, "calibration": {"file": ")" + calibration.string() + R"("}, "camera": {"device": "fake:)" +
           (icewatch::test::sourceDir() / "tools" / "demo" / "recording").string() + R"("},
              "gpio": {"chip": "fake:)" + (dir / "gpio.log").string() + R"("},
              "http": {"port": 0, "token_file": ")" + (dir / "http-token").string() + R"("}})";
}

class Process {
public:
    Process(const std::filesystem::path& dir, const std::vector<std::string>& args) : socketPath_(dir / "notify") {
        socket_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        std::strncpy(addr.sun_path, socketPath_.c_str(), sizeof addr.sun_path - 1);
        if (::bind(socket_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
            throw std::runtime_error("cannot bind " + socketPath_.string());
        }
        std::vector<std::string> env{"NOTIFY_SOCKET=" + socketPath_.string()};
        for (char** e = environ; *e != nullptr; ++e) {
            if (std::string(*e).rfind("NOTIFY_SOCKET=", 0) != 0) env.emplace_back(*e);
        }
        std::vector<char*> envp, argv;
        for (auto& e : env) envp.push_back(e.data());
        envp.push_back(nullptr);
        std::vector<std::string> all{(icewatch::test::binDir() / "icewatchd").string()};
        all.insert(all.end(), args.begin(), args.end());
        for (auto& a : all) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        const std::string log = (dir / "icewatchd.log").string();
        posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
        posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
        if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), envp.data()) != 0) {
            throw std::runtime_error("cannot start icewatchd");
        }
        posix_spawn_file_actions_destroy(&actions);
    }
    ~Process() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        ::close(socket_);
    }

    // The next sd_notify datagram containing `what`, or "" when none came in time.
    std::string awaitNotify(const std::string& what) {
        pollfd p{socket_, POLLIN, 0};
        while (::poll(&p, 1, kGuardMs) == 1) {
            char buffer[4096];
            const ssize_t n = ::recv(socket_, buffer, sizeof buffer, 0);
            if (n <= 0) break;
            const std::string message(buffer, static_cast<std::size_t>(n));
            if (message.find(what) != std::string::npos) return message;
        }
        return "";
    }

    void signal(int s) { ::kill(pid_, s); }

    // Exit status, or -1 when it did not exit within the guard.
    int awaitExit() {
        for (int waited = 0; waited < kGuardMs; waited += 10) {
            int status = 0;
            if (::waitpid(pid_, &status, WNOHANG) == pid_) {
                pid_ = -1;
                return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        return -1;
    }

private:
    std::filesystem::path socketPath_;
    int socket_ = -1;
    pid_t pid_ = -1;
};

int portFrom(const std::string& ready) {
    const std::string marker = "http 127.0.0.1:";
    const auto at = ready.find(marker);
    return at == std::string::npos ? 0 : std::atoi(ready.c_str() + at + marker.size());
}

TEST(Icewatchd, ReadySighupWithABadConfigKeepsTheOldOneSigtermExitsClean) {
    const auto dir = icewatch::test::freshTempDir();
    const auto configFile = dir / "icewatch.json";
    std::ofstream(configFile) << configText(dir);
    Process daemon(dir, {"--config", configFile.string()});
    const std::string ready = daemon.awaitNotify("READY=1");
    ASSERT_FALSE(ready.empty()) << "no READY=1";
    const int port = portFrom(ready);
    ASSERT_GT(port, 0) << ready;
    httplib::Client client("127.0.0.1", port);

    auto health = [&] {
        auto r = client.Get("/v1/health");
        return r ? nlohmann::json::parse(r->body, nullptr, false) : nlohmann::json();
    };
    const std::string firstSha = health()["config_sha256"];
    EXPECT_EQ(firstSha.size(), 64u);

    std::ofstream(configFile) << R"({"daemon": {"interval_s": 5}})";  // below the minimum
    daemon.signal(SIGHUP);
    nlohmann::json h;
    for (int waited = 0; waited < kGuardMs; waited += 20) {
        h = health();
        if (h.is_object() && h["reloads"]["count"] == 1) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_EQ(h["reloads"]["failed"], 1);
    EXPECT_NE(h["reloads"]["last_error"].get<std::string>().find("daemon.interval_s: must be between 10 and 86400"),
              std::string::npos)
        << h["reloads"]["last_error"];
    EXPECT_EQ(h["config_sha256"], firstSha) << "the old configuration stays";
    EXPECT_EQ(h["interval_s"], 600);
    EXPECT_EQ(h["alarm"], "fault") << "no baseline in this test: never shown as no ice";

    // A number no double holds threw past every catch and killed the daemon (exit 70).
    std::filesystem::copy_file(icewatch::test::sourceDir() / "tests/core/config/bad-inputs/overflow.json", configFile,
                               std::filesystem::copy_options::overwrite_existing);
    daemon.signal(SIGHUP);
    for (int waited = 0; waited < kGuardMs; waited += 20) {
        h = health();
        if (h.is_object() && h["reloads"]["count"] == 2) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_TRUE(h.is_object()) << "the daemon still answers";
    EXPECT_EQ(h["reloads"]["failed"], 2);
    EXPECT_NE(h["reloads"]["last_error"].get<std::string>().find("daemon.interval_s: the number 1e999"),
              std::string::npos)
        << h["reloads"]["last_error"];
    EXPECT_EQ(h["config_sha256"], firstSha);

    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.awaitExit(), 0);
    // Whatever the lines did, both end de-energised: fault and alarm for SCADA.
    bool alarmEnergised = false, healthyEnergised = false;
    for (const auto& t : gpio::readTransitionFile(dir / "gpio.log")) {
        (t.line == "alarm" ? alarmEnergised : healthyEnergised) = t.energised;
    }
    EXPECT_FALSE(alarmEnergised);
    EXPECT_FALSE(healthyEnergised);
    const auto latest = nlohmann::json::parse(std::ifstream(dir / "state" / "latest.json"), nullptr, false);
    EXPECT_TRUE(latest.is_object()) << "latest.json is valid after the stop";
}

TEST(Icewatchd, OncePrintsTheResultAndItsStatus) {
    const auto dir = icewatch::test::freshTempDir();
    const auto configFile = dir / "icewatch.json";
    std::ofstream(configFile) << configText(dir);
    const auto run = icewatch::test::runProgram(
        {(icewatch::test::binDir() / "icewatchd").string(), "--config", configFile.string(), "--once"});
    const auto doc = nlohmann::json::parse(run.out, nullptr, false);
    ASSERT_TRUE(doc.is_object()) << run.out << run.err;
    const std::map<std::string, int> statusOf{{"ok", 0}, {"refused", 1}, {"no_baseline", 66}, {"fault", 75}};
    ASSERT_TRUE(statusOf.count(doc["status"]));
    EXPECT_EQ(run.status, statusOf.at(doc["status"])) << run.err;
    EXPECT_EQ(doc["status"], "no_baseline") << run.err;
    EXPECT_EQ(doc["camera"], "ok") << "the demo recording plays through the fake camera";
    EXPECT_TRUE(std::filesystem::exists(dir / "state" / "latest.json"));
}

TEST(Icewatchd, InvalidConfigurationExits78) {
    const auto dir = icewatch::test::freshTempDir();
    const auto configFile = dir / "icewatch.json";
    std::ofstream(configFile) << R"({"alarm": {"warning_set": 1, "warning_clear": 2}})";
    const auto run = icewatch::test::runProgram(
        {(icewatch::test::binDir() / "icewatchd").string(), "--config", configFile.string(), "--once"});
    EXPECT_EQ(run.status, 78);
    EXPECT_NE(run.err.find("alarm.warning_clear: must be below warning_set"), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "state")) << "no state touched";
}

// The blade demo's clean recording, measured against itself, through a camera whose faults are
// set in camera.device.
std::string faultyCameraConfig(const std::filesystem::path& dir, const std::string& device) {
    const auto blade = icewatch::test::sourceDir() / "tools" / "demo" / "blade";
    nlohmann::json config = nlohmann::json::parse(std::ifstream(blade / "icewatch-baseline.json"), nullptr, false);
    config["calibration"]["file"] = (blade / "calibration.yaml").string();
    config["camera"]["device"] = device;
    config["camera"]["frame_timeout_ms"] = 300;
    config["camera"]["reconnect_min_ms"] = 10;
    config["camera"]["reconnect_max_ms"] = 50;
    config["daemon"]["interval_s"] = 3600;
    config["daemon"]["camera_check_s"] = 1;
    // Short bursts, so that the faults below fall into the cycles they are meant for.
    config["daemon"]["burst_frames"] = 3;
    config["daemon"]["baseline_frames"] = 3;
    config["daemon"]["min_frames"] = 2;
    config["daemon"]["state_dir"] = (dir / "state").string();
    config["gpio"]["chip"] = "fake:" + (dir / "gpio.log").string();
    config["http"] = {{"port", 0}, {"token_file", (dir / "http-token").string()}};
    config["log"]["level"] = "debug";  // dropped frames are logged at debug
    return config.dump(2);
}

TEST(Icewatchd, ComesThroughUnplugStallAndCorruptFramesOfTheCamera) {
    const auto dir = icewatch::test::freshTempDir();
    const std::string recording = (icewatch::test::sourceDir() / "tools/demo/blade/baseline").string();
    std::ofstream(dir / "baseline.json") << faultyCameraConfig(dir, "fake:" + recording);
    const auto baseline = icewatch::test::runProgram({(icewatch::test::binDir() / "icewatch").string(), "baseline",
                                                      "capture", "--config", (dir / "baseline.json").string()});
    ASSERT_EQ(baseline.status, 0) << baseline.err;

    // Frame 1 arrives cut in half, frame 7 unplugs the camera, frame 14 stalls it. At pace=fast a
    // frame is made only when the daemon waits for one, so the order does not depend on timing.
    const auto configFile = dir / "icewatch.json";
    std::ofstream(configFile) << faultyCameraConfig(
        dir, "fake:" + recording + "?pace=fast&truncate=1&unplug_at=7&stall_at=14&replug_after=1");
    Process daemon(dir, {"--config", configFile.string()});
    ASSERT_FALSE(daemon.awaitNotify("READY=1").empty());

    // SCADA's view: healthy on the first result, dropped at the unplug, back, dropped at the stall, back.
    const std::vector<bool> expected{true, false, true, false, true};
    std::vector<bool> healthy;
    for (int waited = 0; waited < 4 * kGuardMs && healthy.size() < expected.size(); waited += 100) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        healthy.clear();
        for (const auto& t : gpio::readTransitionFile(dir / "gpio.log")) {
            if (t.line == "healthy" && (healthy.empty() ? t.energised : t.energised != healthy.back())) {
                healthy.push_back(t.energised);
            }
        }
    }
    EXPECT_EQ(healthy, expected);
    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.awaitExit(), 0);

    std::ifstream logFile(dir / "icewatchd.log");
    const std::string log((std::istreambuf_iterator<char>(logFile)), std::istreambuf_iterator<char>());
    EXPECT_NE(log.find(": dropped frame "), std::string::npos) << "the cut frame was dropped, not measured";
    EXPECT_NE(log.find("offline (disconnected)"), std::string::npos);
    EXPECT_NE(log.find("offline (stalled)"), std::string::npos);
    const auto latest = nlohmann::json::parse(std::ifstream(dir / "state" / "latest.json"), nullptr, false);
    EXPECT_EQ(latest["status"], "ok") << latest;
    EXPECT_EQ(latest["alarm"], "none") << latest;
}

TEST(Icewatchd, FirstStartWithoutCalibrationOrGpioChip) {
    const auto dir = icewatch::test::freshTempDir();
    const auto configFile = dir / "icewatch.json";
    nlohmann::json config = nlohmann::json::parse(configText(dir));
    const auto calibration = dir / "installed-later.yaml";
    config["calibration"]["file"] = calibration.string();
    config["gpio"]["chip"] = "gpiochip193";  // no such device on this machine
    std::ofstream(configFile) << config.dump(2);
    Process daemon(dir, {"--config", configFile.string()});
    const std::string ready = daemon.awaitNotify("READY=1");
    ASSERT_FALSE(ready.empty()) << "it did not come up";
    httplib::Client client("127.0.0.1", portFrom(ready));
    const auto healthUntil = [&](const std::function<bool(const nlohmann::json&)>& done) {
        nlohmann::json h;
        for (int waited = 0; waited < kGuardMs; waited += 20) {
            if (auto r = client.Get("/v1/health"); r && r->status == 503) {
                h = nlohmann::json::parse(r->body, nullptr, false);
                if (h.is_object() && done(h)) break;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        return h;
    };
    nlohmann::json h = healthUntil([](const nlohmann::json& j) { return !j["last_result"].is_null(); });
    ASSERT_TRUE(h.is_object());
    const std::string reasons = h["reasons"].dump();
    EXPECT_NE(reasons.find("no calibration: run icewatch calibrate"), std::string::npos) << reasons;
    EXPECT_NE(reasons.find("--out " + calibration.string()), std::string::npos) << reasons;
    EXPECT_NE(reasons.find("no GPIO chip gpiochip193"), std::string::npos) << reasons;
    EXPECT_EQ(h["alarm"], "fault");
    auto latest = client.Get("/v1/latest");
    ASSERT_TRUE(latest);
    EXPECT_EQ(nlohmann::json::parse(latest->body)["status"], "fault");

    calib::saveCalibration(calibration, calib::nominalCalibration({1280, 720}, 80.0, 60.0));
    daemon.signal(SIGHUP);
    h = healthUntil([](const nlohmann::json& j) { return j["reasons"].dump().find("no calibration") == std::string::npos; });
    EXPECT_EQ(h["reasons"].dump().find("no calibration"), std::string::npos) << h["reasons"];
    EXPECT_NE(h["reasons"].dump().find("no GPIO chip gpiochip193"), std::string::npos) << "still no chip";

    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.awaitExit(), 0) << "it never exited on its own";
}

TEST(Icewatchd, FailSafeOutputsDropTheLinesWhateverElseTheFileGetsWrong) {
    const auto dir = icewatch::test::freshTempDir();
    const auto configFile = dir / "icewatch.json";
    const auto failSafe = [&] {
        return icewatch::test::runProgram({(icewatch::test::binDir() / "icewatchd").string(), "--config",
                                           configFile.string(), "--fail-safe-outputs"});
    };
    // Only the gpio section is read: the rest of the file may be wrong.
    std::ofstream(configFile) << R"({"daemon": {"interval_s": "often"}, "camera": {"nonsense": 1},
                                     "gpio": {"chip": "fake:)" + (dir / "gpio.log").string() + R"("}})";
    auto run = failSafe();
    EXPECT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.err.find("alarm line 17 and healthy line 27 of fake:" + (dir / "gpio.log").string() + " de-energised"),
              std::string::npos)
        << run.err;
    // A file that is not even JSON (a number no double holds): the compiled-in gpio settings are
    // dropped, never a config error.
    std::filesystem::copy_file(icewatch::test::sourceDir() / "tests/core/config/bad-inputs/overflow.json", configFile,
                               std::filesystem::copy_options::overwrite_existing);
    run = failSafe();
    EXPECT_NE(run.err.find("dropping the outputs of the default gpio settings (chip gpiochip0"), std::string::npos)
        << run.err;
    EXPECT_NE(run.status, 78) << run.err;
    // A chip that does not exist holds no line energised: that is success, so the unit's
    // ExecStopPost does not mark every stop of a box without its I/O board as failed.
    std::ofstream(configFile) << R"({"gpio": {"chip": "gpiochip193"}})";
    run = failSafe();
    EXPECT_EQ(run.status, 0) << run.err;
    EXPECT_NE(run.err.find("no GPIO chip gpiochip193 (/dev/gpiochip193 does not exist; gpio.chip): no line is energised"),
              std::string::npos)
        << run.err;
}

TEST(Icewatchd, EnsureTokenMakesAPrivateTokenFileOnce) {
    const auto dir = icewatch::test::freshTempDir();
    const auto configFile = dir / "icewatch.json";
    std::ofstream(configFile) << configText(dir);
    const std::vector<std::string> args{(icewatch::test::binDir() / "icewatchd").string(), "--config",
                                        configFile.string(), "--ensure-token"};
    ASSERT_EQ(icewatch::test::runProgram(args).status, 0);
    const auto status = std::filesystem::status(dir / "http-token");
    EXPECT_EQ(status.permissions() & std::filesystem::perms::all,
              std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                  std::filesystem::perms::group_read);
    std::string first;
    std::getline(std::ifstream(dir / "http-token"), first);
    EXPECT_EQ(first.size(), 64u);
    ASSERT_EQ(icewatch::test::runProgram(args).status, 0);
    std::string second;
    std::getline(std::ifstream(dir / "http-token"), second);
    EXPECT_EQ(first, second) << "an existing token is kept";
}

}  // namespace
}  // namespace icewatch::daemon::test
