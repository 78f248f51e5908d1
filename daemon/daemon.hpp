#pragma once

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/alarm/alarm_state.hpp"
#include "core/config/config.hpp"
#include "daemon/clock.hpp"
#include "daemon/cycle_result.hpp"
#include "daemon/frame_source.hpp"
#include "daemon/history.hpp"
#include "daemon/http_token.hpp"
#include "daemon/measurement_chain.hpp"
#include "daemon/notifier.hpp"
#include "daemon/scada/publication.hpp"
#include "daemon/state_dir.hpp"
#include "drivers/gpio/scada_outputs.hpp"

namespace icewatch::daemon {

struct DaemonOptions {
    std::filesystem::path configFile;  // re-read on reload; empty: reload keeps the current config
    std::string configSha256;          // of the loaded file's bytes
    std::string version;
};

// The parts the daemon composes; the tests pass doubles. outputs may be null (--once: SCADA lines
// belong to the running service).
//
// A first start may lack the calibration or the GPIO chip. A chain or outputs left null with its
// factory set is made by the factory (which throws Error saying what is missing) at once, again
// on SIGHUP and every daemon.camera_check_s; until then the service runs, serves its interfaces
// and reports the level fault with that reason, instead of exiting into a restart loop.
struct DaemonParts {
    DaemonParts() = default;
    DaemonParts(std::unique_ptr<FrameSource> s, std::unique_ptr<MeasurementChain> c,
                std::unique_ptr<gpio::ScadaOutputs> o)
        : source(std::move(s)), chain(std::move(c)), outputs(std::move(o)) {}

    std::unique_ptr<FrameSource> source;
    std::unique_ptr<MeasurementChain> chain;
    std::unique_ptr<gpio::ScadaOutputs> outputs;
    std::function<std::unique_ptr<MeasurementChain>()> makeChain;
    std::function<std::unique_ptr<gpio::ScadaOutputs>()> openOutputs;
};

// icewatchd's service loop: measures every daemon.interval_s and on request, watches the camera
// between cycles, publishes (latest.json, history, pictures, alarm outputs) and answers the HTTP
// API's questions. All work happens on the thread calling run(); request*() and the views may be
// called from any thread (signal thread, HTTP workers).
class Daemon {
public:
    // Takes the state directory (config.daemon.state_dir) and its lock, opens the history and
    // loads the stored baseline. Throws Error on an unusable state directory.
    Daemon(config::Config config, DaemonOptions options, Clock& clock, DaemonParts parts, Notifier* notifier = nullptr);
    // Releases the camera and leaves the outputs fail-safe.
    ~Daemon();
    Daemon(const Daemon&) = delete;
    Daemon& operator=(const Daemon&) = delete;

    // Runs until requestStop(). Sends READY=1 (with readyStatus) on entry.
    void run();
    // Runs until the clock reaches end (simulated time in tests) or requestStop().
    void runUntil(TimePoint end);
    // One cycle now, published like any other; nullopt when a stop request abandoned it.
    std::optional<CycleResult> runOnce();

    void requestStop();
    void requestMeasure();
    // who: logged and stored with the baseline ("http 127.0.0.1 (curl/7.88.1)").
    void requestBaseline(std::string who = "service");
    void requestBaselineRestore(std::string who = "service");
    void requestAlarmReset();
    void requestReload();
    void setReadyStatus(std::string status);
    // The SCADA interfaces, told of every document written to latest.json. Set before run().
    void setPublicationSink(scada::PublicationSink* sink) { sink_ = sink; }

    // Views for the HTTP API.
    std::optional<nlohmann::json> latest() const;  // with "stale"; nullopt before the first result
    nlohmann::json health() const;
    std::vector<nlohmann::json> history(TimePoint since, int limit) const;
    std::optional<std::string> picture(const std::string& name) const;  // PNG bytes
    HttpToken token() const;
    // The level when the current result shows ice (warning or alarm), else nullopt.
    std::optional<std::string> iceShown() const;
    TimePoint now() const { return clock_.now(); }
    const std::string& version() const { return options_.version; }
    alarm::AlarmLevel alarmLevel() const;
    const std::filesystem::path& stateDir() const { return stateDir_; }

private:
    struct Requests {
        bool measure = false, baseline = false, baselineRestore = false, alarmReset = false, reload = false;
        std::string baselineBy, restoreBy;
    };
    void loop(std::optional<TimePoint> end);
    Requests takeRequests();
    void waitUntil(TimePoint deadline);
    std::optional<CycleResult> runCycle();
    void checkCamera();
    void captureBaseline(const std::string& who);
    void restorePreviousBaseline(const std::string& who);
    void resetAlarm();
    // daemon.max_refused_s: true when the level became fault just now for want of an ok result.
    bool faultIfUnmeasured(TimePoint now);
    // The latest result again with the alarm level as it is now (a reset, a fault by age).
    void republishAlarm();
    void reload();
    void loadStoredBaseline();
    // Makes the parts a first start lacked; requests a measurement when the last one arrives.
    void completeParts();
    // Why the service cannot measure or signal yet ("no calibration: ...; no GPIO chip ..."), or "".
    std::string missingParts() const;
    // Applies the alarm level and writes everything out; returns the result as published.
    CycleResult publish(CycleResult result, const ChainPictures& pictures, bool toHistory);
    // The loop (or a cycle, or the chain between its stages) is making progress: WATCHDOG=1 once
    // the loop runs; before (a stored baseline measured at start) the start timeout is extended
    // by a stage's allowance instead, so that a slow box is not killed while it starts.
    void progress();
    // The chain reports its stages to progress().
    void attachChain();
    bool stopping() const { return stop_.load(); }

    config::Config config_;  // guarded by mutex_ for the views; written on the loop thread only
    DaemonOptions options_;
    Clock& clock_;
    DaemonParts parts_;
    Notifier* notifier_;
    std::filesystem::path stateDir_;
    StateDirLock lock_;
    History history_;
    alarm::AlarmStateMachine alarm_;
    std::optional<TimePoint> lastOk_;  // the latest ok result's time; loop thread only

    mutable std::mutex mutex_;
    std::condition_variable wake_;
    Requests requests_;
    std::atomic<bool> stop_{false};
    std::string readyStatus_;
    bool ready_ = false;  // READY=1 sent; loop thread only
    std::optional<nlohmann::json> latest_;
    CameraState camera_ = CameraState::Offline;
    std::string cameraDetail_;
    std::string chainMissing_;    // why parts_.chain is still null; guarded by mutex_
    std::string outputsMissing_;  // why parts_.outputs is still null; guarded by mutex_
    TimePoint nextCycle_{};
    TimePoint nextCheck_{};     // loop thread only
    bool scheduled_ = false;    // loop thread only
    nlohmann::json baselineInfo_;      // null or {time, calibration_sha256}
    nlohmann::json lastBaselineCapture_;
    int reloads_ = 0;
    int failedReloads_ = 0;
    std::string lastReloadError_;
    HttpToken token_;
    std::string storageFault_;   // empty: the last writes of latest.json and the history succeeded
    bool latestWriteFailed_ = false;
    std::chrono::steady_clock::time_point lastWatchdog_{};
    scada::PublicationSink* sink_ = nullptr;  // called on the loop thread, with mutex_ held
};

}  // namespace icewatch::daemon
