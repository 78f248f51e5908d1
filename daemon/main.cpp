// icewatchd: the unattended service. Parses the command line, loads the configuration, wires the
// parts, handles signals on a dedicated thread (all signals are blocked everywhere else, so no
// work ever runs in a signal handler) and runs the service loop.
//   SIGTERM/SIGINT  finish or abandon the cycle, release camera and GPIO (fail-safe), exit 0
//   SIGHUP          re-read the configuration; an invalid one is logged and the old one kept
//   SIGUSR1         measure now
//   SIGUSR2         reset a latched alarm
#include <malloc.h>
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <iostream>
#include <thread>

#include <CLI/CLI.hpp>

#include "core/common/error.hpp"
#include "core/config/config.hpp"
#include "daemon/daemon.hpp"
#include "daemon/http_api.hpp"
#include "daemon/http_token.hpp"
#include "daemon/scada/scada_interfaces.hpp"
#include "daemon/sha256.hpp"
#include "daemon/wiring.hpp"
#include "drivers/log/log.hpp"

namespace {

using namespace icewatch;

sigset_t handledSignals() {
    sigset_t set;
    sigemptyset(&set);
    for (int s : {SIGTERM, SIGINT, SIGHUP, SIGUSR1, SIGUSR2}) sigaddset(&set, s);
    return set;
}

// Turns signals into requests until told to finish.
class SignalThread {
public:
    explicit SignalThread(daemon::Daemon& d) : thread_([this, &d] { loop(d); }) {}
    ~SignalThread() {
        finished_ = true;
        pthread_kill(thread_.native_handle(), SIGUSR2);
        thread_.join();
    }

private:
    void loop(daemon::Daemon& d) {
        const sigset_t set = handledSignals();
        while (true) {
            int signal = 0;
            if (sigwait(&set, &signal) != 0 || finished_) return;
            switch (signal) {
                case SIGTERM:
                case SIGINT: log::get("daemon")->info("signal {}: stopping", signal); d.requestStop(); break;
                case SIGHUP: d.requestReload(); break;
                case SIGUSR1: d.requestMeasure(); break;
                case SIGUSR2: d.requestAlarmReset(); break;
                default: break;
            }
        }
    }
    std::atomic<bool> finished_{false};
    std::thread thread_;
};

int exitStatusOf(daemon::CycleStatus status) {
    switch (status) {
        case daemon::CycleStatus::Ok: return kExitOk;
        case daemon::CycleStatus::Refused: return kExitFailure;
        case daemon::CycleStatus::NoBaseline: return kExitNoInput;
        case daemon::CycleStatus::Fault: return kExitTempFail;
    }
    return kExitSoftware;
}

// ExecStopPost: whatever became of the service, leave SCADA reading fault and alarm. Only the gpio
// section is read, and a file that cannot even give that still gets the lines dropped on the
// compiled-in defaults.
int failSafeOutputs(const std::string& configFile) {
    std::string problem;
    const config::GpioConfig gpio = config::loadGpioSection(configFile, problem);
    if (!problem.empty()) {
        log::get("daemon")->error("{}; dropping the outputs of the default gpio settings (chip {}, lines {} and {})",
                                  problem, gpio.chip, gpio.alarmLine, gpio.healthyLine);
    }
    if (const auto missing = daemon::missingGpioChip(gpio)) {
        // No chip, no driver: nothing can hold a line energised (a box without its I/O board).
        log::get("daemon")->warn("{}: no line is energised", *missing);
        return kExitOk;
    }
    if (!gpio::openScadaOutputs(gpio)->failSafe()) {
        throw Error(kExitUnavailable, "could not drop every output line of chip " + gpio.chip);
    }
    log::get("daemon")->info("alarm line {} and healthy line {} of {} de-energised", gpio.alarmLine, gpio.healthyLine,
                             gpio.chip);
    return kExitOk;
}

// ExecStartPre (as root): makes http.token_file when no token is configured, so that the service
// user can read it and nobody else.
int ensureToken(const config::Config& config) {
    const daemon::HttpToken token = daemon::resolveHttpToken(config.http, /*create=*/true);
    if (token.value.empty()) {
        throw Error(kExitCantCreate, "http token: " + token.problem);
    }
    return kExitOk;
}

int serve(const std::string& configFile, const std::string& stateDir, bool once, bool ensureTokenOnly) {
    config::Config config = config::loadConfig(configFile);
    if (!stateDir.empty()) {
        config.daemon.stateDir = stateDir;
    }
    log::setLevel(config.log.level);
    if (ensureTokenOnly) {
        return ensureToken(config);
    }
    daemon::DaemonOptions options{configFile, daemon::sha256OfFile(configFile).value_or(""), ICEWATCH_VERSION};
    // The calibration and the GPIO chip may be missing on a first start: the daemon reports that
    // and retries (DaemonParts), rather than exiting into systemd's restart loop.
    daemon::DaemonParts parts;
    parts.source = daemon::makeFrameSource(config);
    parts.makeChain = [&config] { return daemon::makeMeasurementChain(config); };
    if (!once) {
        parts.openOutputs = [&config] { return daemon::openAlarmOutputs(config.gpio); };
    }
    daemon::SystemClock clock;
    daemon::SystemdNotifier notifier;
    // With Modbus on, the loop's watchdog pings also drive the heartbeat register.
    daemon::scada::LoopHeartbeat heartbeat(notifier);
    daemon::Notifier* loopNotifier = config.scada.modbus.listen.empty() ? static_cast<daemon::Notifier*>(&notifier)
                                                                        : &heartbeat;
    daemon::Daemon service(config, options, clock, std::move(parts), once ? nullptr : loopNotifier);
    SignalThread signals(service);
    if (once) {
        const auto result = service.runOnce();
        if (!result) {
            return kExitOk;  // stopped by a signal before the cycle finished
        }
        std::cout << service.latest()->dump(2) << "\n";
        return exitStatusOf(result->status);
    }
    // SCADA interfaces belong to the running service, as the GPIO lines do (none with --once).
    // They start first: a Modbus port in use ends the start before the HTTP server runs.
    std::unique_ptr<daemon::scada::ScadaInterfaces> scada;
    if (!config.scada.modbus.listen.empty() || !config.scada.mqtt.broker.empty()) {
        scada = std::make_unique<daemon::scada::ScadaInterfaces>(config.scada, service, &heartbeat);
        service.setPublicationSink(scada.get());
    }
    std::string ready = "measuring every " + std::to_string(config.daemon.intervalS) + " s";
    std::unique_ptr<daemon::HttpApi> http;
    if (config.http.enabled) {
        http = std::make_unique<daemon::HttpApi>(service, config.http);
        ready += ", http " + config.http.address + ":" + std::to_string(http->port());
    }
    if (scada) ready += ", " + scada->summary();
    service.setReadyStatus(ready);
    service.run();
    log::get("daemon")->info("stopped");
    return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
    // Block before any thread exists so that every thread inherits the mask.
    const sigset_t set = handledSignals();
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    // Every block of a megabyte or more (frames, surfaces, the matcher's volumes) straight from
    // mmap and back to the system when freed. glibc's adaptive threshold otherwise serves them from
    // the heap after the first cycle, where a freed block may stay resident: the daemon's memory
    // then swung between 527 and 582 MB from one cycle to the next at 3840x1080.
    mallopt(M_MMAP_THRESHOLD, 1 << 20);

    CLI::App app{"icewatchd: measures the ice on a parked blade, publishes it and signals SCADA"};
    std::string configFile = "/etc/icewatch/icewatch.json";
    std::string stateDir;
    bool once = false, failSafe = false, makeToken = false, verbose = false;
    app.add_option("--config", configFile, "configuration file")->capture_default_str();
    app.add_option("--state-dir", stateDir, "state directory (overrides daemon.state_dir)");
    app.add_flag("--once", once,
                 "one cycle, result JSON on stdout; exit 0 ok, 1 refused, 66 no baseline, 75 fault");
    app.add_flag("--fail-safe-outputs", failSafe,
                 "de-energise the alarm and healthy lines and exit (reads only the gpio section)");
    app.add_flag("--ensure-token", makeToken, "create http.token_file with a random token when missing, and exit");
    app.add_flag("-v,--verbose", verbose, "log debug messages");
    app.set_version_flag("--version", std::string(ICEWATCH_VERSION));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int status = app.exit(e);
        return status == 0 ? 0 : kExitUsage;
    }
    log::setup(verbose ? "debug" : "info");
    try {
        if (failSafe) {
            return failSafeOutputs(configFile);
        }
        return serve(configFile, stateDir, once, makeToken);
    } catch (const Error& e) {
        log::get("daemon")->critical("{}", e.what());
        return e.code();
    } catch (const std::exception& e) {
        log::get("daemon")->critical("internal error: {}", e.what());
        return kExitSoftware;
    }
}
