#pragma once

// A daemon on simulated time with scripted camera and chain and fake GPIO lines.
#include <fstream>
#include <memory>

#include <nlohmann/json.hpp>

#include "daemon/daemon.hpp"
#include "tests/daemon/doubles.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::daemon::test {

inline nlohmann::json readJsonFile(const std::filesystem::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in, nullptr, false);
}

struct Rig {
    explicit Rig(const std::function<void(config::Config&)>& adjust = {},
                 std::filesystem::path stateDir = icewatch::test::freshTempDir(),
                 const std::function<void(ScriptedChain&)>& adjustChain = {})
        : dir(std::move(stateDir)), clock(testEpoch()) {
        config = testConfig(dir);
        if (adjust) adjust(config);
        auto s = std::make_unique<ScriptedSource>();
        auto c = std::make_unique<ScriptedChain>();
        if (adjustChain) adjustChain(*c);
        source = s.get();
        chain = c.get();
        DaemonParts parts{std::move(s), std::move(c), gpio::openScadaOutputs(config.gpio, gpioLog)};
        daemon = std::make_unique<Daemon>(config, DaemonOptions{configFile, "cafe", "test-version"}, clock,
                                          std::move(parts));
    }

    TimePoint at(int seconds) const { return testEpoch() + std::chrono::seconds(seconds); }
    nlohmann::json latestFile() const { return readJsonFile(dir / "latest.json"); }
    std::vector<gpio::LineTransition> transitions() const { return gpioLog->transitions(); }

    std::filesystem::path dir;
    std::filesystem::path configFile;
    ManualClock clock;
    config::Config config;
    std::shared_ptr<gpio::TransitionLog> gpioLog = std::make_shared<gpio::TransitionLog>();
    ScriptedSource* source = nullptr;
    ScriptedChain* chain = nullptr;
    std::unique_ptr<Daemon> daemon;
};

}  // namespace icewatch::daemon::test
