// icewatch baseline capture: takes the clean-blade reference with the daemon's own camera and
// chain settings and stores it in the state directory with its time and calibration hash. With
// icewatchd running the state directory is locked: use POST /v1/baseline instead.
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

void addBaselineCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* baseline = app.add_subcommand("baseline", "the clean-blade reference");
    baseline->require_subcommand(1);
    CLI::App* capture = baseline->add_subcommand("capture", "capture and store the baseline now");
    struct Options {
        std::string config = "/etc/icewatch/icewatch.json", stateDir;
    };
    auto o = std::make_shared<Options>();
    capture->add_option("--config", o->config, "configuration file")->capture_default_str();
    capture->add_option("--state-dir", o->stateDir, "state directory (overrides daemon.state_dir)");
    capture->callback([&run, o] {
        run = [o] {
            config::Config config = config::loadConfig(o->config);
            if (!o->stateDir.empty()) config.daemon.stateDir = o->stateDir;
            daemon::prepareStateDir(config.daemon.stateDir);
            const daemon::StateDirLock lock(config.daemon.stateDir);
            auto source = daemon::makeFrameSource(config);
            auto chain = daemon::makeMeasurementChain(config);
            daemon::BaselineCapture captured = daemon::captureBaselinePair(
                *source, *chain, config.daemon, [] { return false; }, [] {});
            source->close();
            if (!captured.ok) {
                throw Error(kExitUnavailable, "baseline capture failed: " + captured.reason);
            }
            const auto time = std::chrono::system_clock::now();
            daemon::BaselineRecord record{time, chain->calibrationSha256(), std::move(captured.pair)};
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
