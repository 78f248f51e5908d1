// icewatch baseline capture: takes the clean-blade reference with the daemon's own camera and
// chain settings and stores it in the state directory with its time and calibration hash; the one
// it replaces is kept. icewatch baseline restore: goes back to that one. With icewatchd running
// the state directory is locked: use POST /v1/baseline (or /v1/baseline/restore) instead.
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "core/common/error.hpp"
#include "core/config/config.hpp"
#include "daemon/baseline_store.hpp"
#include "daemon/iso_time.hpp"
#include "daemon/measurement_cycle.hpp"
#include "daemon/state_dir.hpp"
#include "daemon/wiring.hpp"
#include "tools/icewatch/command.hpp"

namespace icewatch::cli {

namespace {

std::filesystem::path stateDirOf(const std::string& configFile, const std::string& stateDir) {
    return stateDir.empty() ? std::filesystem::path(config::loadConfig(configFile).daemon.stateDir)
                            : std::filesystem::path(stateDir);
}

// The alarm level of STATE_DIR/latest.json when it is warning or alarm, else empty.
std::string iceInLatest(const std::filesystem::path& stateDir) {
    std::ifstream in(stateDir / "latest.json");
    const auto doc = nlohmann::json::parse(in, nullptr, false);
    if (!doc.is_object() || !doc.contains("alarm") || !doc["alarm"].is_string()) return {};
    const std::string level = doc["alarm"].get<std::string>();
    return level == "warning" || level == "alarm" ? "alarm level " + level : std::string();
}

}  // namespace

void addBaselineCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* baseline = app.add_subcommand("baseline", "the clean-blade reference");
    baseline->require_subcommand(1);
    CLI::App* capture = baseline->add_subcommand("capture", "capture and store the baseline now");
    CLI::App* restore = baseline->add_subcommand("restore", "go back to the baseline the last capture replaced");
    struct Options {
        std::string config = "/etc/icewatch/icewatch.json", stateDir;
        bool force = false;
    };
    auto o = std::make_shared<Options>();
    for (CLI::App* sub : {capture, restore}) {
        sub->add_option("--config", o->config, "configuration file")->capture_default_str();
        sub->add_option("--state-dir", o->stateDir, "state directory (overrides daemon.state_dir)");
    }
    capture->add_flag("--force", o->force, "capture even though the last result shows ice");
    restore->callback([&run, o] {
        run = [o] {
            const std::filesystem::path stateDir = stateDirOf(o->config, o->stateDir);
            const daemon::StateDirLock lock(stateDir);
            std::string error;
            if (!daemon::restoreBaseline(stateDir, error)) {
                throw Error(kExitNoInput, error);
            }
            std::cout << nlohmann::json{{"restored", (stateDir / "baseline").string()}}.dump() << "\n";
            return kExitOk;
        };
    });
    capture->callback([&run, o] {
        run = [o] {
            config::Config config = config::loadConfig(o->config);
            if (!o->stateDir.empty()) config.daemon.stateDir = o->stateDir;
            daemon::prepareStateDir(config.daemon.stateDir);
            const daemon::StateDirLock lock(config.daemon.stateDir);
            if (const std::string ice = iceInLatest(config.daemon.stateDir); !ice.empty() && !o->force) {
                throw Error(kExitDataErr, "the last result shows ice (" + ice +
                                              "): a baseline now would make that ice the clean reference; "
                                              "add --force if the blade is clean");
            }
            auto source = daemon::makeFrameSource(config);
            auto chain = daemon::makeMeasurementChain(config);
            daemon::BaselineCapture captured = daemon::captureBaselinePair(
                *source, *chain, config.daemon, [] { return false; }, [] {});
            source->close();
            if (!captured.ok) {
                throw Error(kExitUnavailable, "baseline capture failed: " + captured.reason);
            }
            const auto time = std::chrono::system_clock::now();
            daemon::BaselineRecord record{time, chain->calibrationSha256(), std::move(captured.pair),
                                          o->force ? "cli, forced" : "cli", std::move(captured.noise)};
            std::string error;
            if (!daemon::saveBaseline(config.daemon.stateDir, record, error)) {
                throw Error(kExitCantCreate, error);
            }
            std::cout << nlohmann::json{{"baseline", (std::filesystem::path(config.daemon.stateDir) / "baseline").string()},
                                        {"time", daemon::formatIsoUtc(time)},
                                        {"calibration_sha256", record.calibrationSha256}}
                             .dump()
                      << "\n";
            return kExitOk;
        };
    });
}

}  // namespace icewatch::cli
