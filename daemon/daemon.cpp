// icewatchd's service loop. One thread does all the work (camera, chain, files, GPIO) so nothing
// in the measurement path needs a lock; other threads only post requests and read published
// snapshots. The loop wakes for the next cycle, the next camera check, the watchdog and requests.
//
// Fault handling: a camera that vanishes between cycles is a fault at once (not at the next
// cycle) and latest.json says so; when it returns a cycle runs straight away, so the fault clears
// with a real measurement rather than by assumption.
#include "daemon/daemon.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "core/common/error.hpp"
#include "daemon/atomic_file.hpp"
#include "daemon/baseline_store.hpp"
#include "daemon/iso_time.hpp"
#include "daemon/measurement_cycle.hpp"
#include "daemon/sha256.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::daemon {

namespace {

std::shared_ptr<spdlog::logger> logger() {
    return log::get("daemon");
}

std::filesystem::path prepared(const std::filesystem::path& dir) {
    prepareStateDir(dir);
    return dir;
}

const std::vector<std::string> kPictureNames{"left", "disparity", "thickness"};

// How long one stage of the chain may take before READY=1, as long as the unit's WatchdogSec
// gives it once the loop runs. A stored 3840x1080 baseline is measured in a few seconds here,
// tens on a slower box: more than systemd's start timeout (90 s) may allow for all of them.
constexpr std::chrono::microseconds kStartStageAllowance = std::chrono::seconds(120);

// A result document as this daemon writes it: the fields every view reads must be there with
// their types. Anything else (a hand-edited or truncated-and-repaired file) counts as absent.
bool isResultDocument(const nlohmann::json& doc) {
    if (!doc.is_object()) return false;
    for (const char* key : {"time", "status", "alarm", "camera"}) {
        if (!doc.contains(key) || !doc[key].is_string()) return false;
    }
    return true;
}

std::string textOf(const nlohmann::json& doc, const char* key, const std::string& otherwise) {
    return doc.is_object() && doc.contains(key) && doc[key].is_string() ? doc[key].get<std::string>() : otherwise;
}

// The settings only a restart applies: they hold devices, sockets and files open.
std::vector<std::string> restartOnlyChanges(const config::Config& a, const config::Config& b) {
    std::vector<std::string> changed;
    if (a.camera.device != b.camera.device || a.camera.width != b.camera.width || a.camera.height != b.camera.height ||
        a.camera.format != b.camera.format || a.camera.fps != b.camera.fps || a.camera.buffers != b.camera.buffers ||
        a.camera.controls != b.camera.controls || a.camera.frameTimeoutMs != b.camera.frameTimeoutMs ||
        a.camera.reconnectMinMs != b.camera.reconnectMinMs || a.camera.reconnectMaxMs != b.camera.reconnectMaxMs) {
        changed.push_back("camera");
    }
    if (a.gpio.chip != b.gpio.chip || a.gpio.alarmLine != b.gpio.alarmLine || a.gpio.healthyLine != b.gpio.healthyLine ||
        a.gpio.activeLow != b.gpio.activeLow || a.gpio.consumer != b.gpio.consumer) {
        changed.push_back("gpio");
    }
    if (a.http.enabled != b.http.enabled || a.http.address != b.http.address || a.http.port != b.http.port) {
        changed.push_back("http.enabled/address/port");
    }
    if (a.daemon.stateDir != b.daemon.stateDir || a.calibration.file != b.calibration.file) {
        changed.push_back("daemon.state_dir/calibration.file");
    }
    return changed;
}

}  // namespace

Daemon::Daemon(config::Config config, DaemonOptions options, Clock& clock, DaemonParts parts, Notifier* notifier)
    : config_(std::move(config)),
      options_(std::move(options)),
      clock_(clock),
      parts_(std::move(parts)),
      notifier_(notifier),
      stateDir_(prepared(config_.daemon.stateDir)),
      lock_(stateDir_),
      history_(stateDir_ / "history.sqlite", History::Mode::ReadWrite, clock_.now()),
      alarm_(config_.alarm),
      token_(resolveHttpToken(config_.http, /*create=*/true)) {
    if (!parts_.source || (!parts_.chain && !parts_.makeChain)) {
        throw Error(kExitSoftware, "daemon: a frame source and a measurement chain are required");
    }
    // The last result survives a restart for GET /v1/latest (it is stale by then, and says so).
    if (std::ifstream in(stateDir_ / "latest.json"); in) {
        auto doc = nlohmann::json::parse(in, nullptr, false);
        if (isResultDocument(doc)) {
            // The age of the latest ok result survives too: a restart does not restart the clock
            // of max_refused_s.
            if (doc.contains("last_ok") && doc["last_ok"].is_string()) {
                lastOk_ = parseIsoUtc(doc["last_ok"].get<std::string>());
            } else if (doc["status"] == "ok") {
                lastOk_ = parseIsoUtc(doc["time"].get<std::string>());
            }
            latest_ = std::move(doc);
        } else {
            logger()->warn("{}: not a result document; ignored", (stateDir_ / "latest.json").string());
        }
    }
    if (token_.value.empty() && config_.http.enabled) {
        logger()->error("no HTTP token ({}): every POST will be refused", token_.problem);
    }
    if (parts_.chain) {
        attachChain();
        loadStoredBaseline();
    }
    if (parts_.outputs) {
        parts_.outputs->show(alarm_.level());
    }
    completeParts();
}

Daemon::~Daemon() {
    parts_.source->close();
    if (parts_.outputs) {
        parts_.outputs->failSafe();
    }
}

namespace {

// One attempt at a missing part; the reason is logged when it changes, not at every retry.
template <typename Part>
bool tryToMake(const std::function<std::unique_ptr<Part>()>& factory, std::unique_ptr<Part>& part, std::string& missing,
          std::mutex& mutex) {
    std::string why;
    try {
        part = factory();
    } catch (const std::exception& e) {
        why = e.what();
    }
    std::lock_guard lock(mutex);
    if (part) {
        missing.clear();
        return true;
    }
    if (why != missing) {
        logger()->error("{}; retried on SIGHUP and every daemon.camera_check_s", why);
    }
    missing = why;
    return false;
}

}  // namespace

void Daemon::completeParts() {
    bool arrived = false;
    if (!parts_.chain && parts_.makeChain && tryToMake(parts_.makeChain, parts_.chain, chainMissing_, mutex_)) {
        logger()->info("calibration {} loaded", config_.calibration.file);
        attachChain();
        loadStoredBaseline();
        arrived = true;
    }
    if (!parts_.outputs && parts_.openOutputs && tryToMake(parts_.openOutputs, parts_.outputs, outputsMissing_, mutex_)) {
        logger()->info("alarm outputs on {} opened", config_.gpio.chip);
        parts_.outputs->show(alarm_.level());
        arrived = true;
    }
    if (!arrived) return;
    if (const std::string missing = missingParts(); !missing.empty()) {
        alarm_.fault(missing);  // the reason shown is what is still missing
        republishAlarm();
        return;
    }
    std::lock_guard lock(mutex_);
    requests_.measure = true;  // the fault clears with a real measurement, not by assumption
}

std::string Daemon::missingParts() const {
    std::lock_guard lock(mutex_);
    if (chainMissing_.empty() || outputsMissing_.empty()) return chainMissing_ + outputsMissing_;
    return chainMissing_ + "; " + outputsMissing_;
}

void Daemon::loadStoredBaseline() {
    if (!parts_.chain) return;  // loaded when the calibration arrives
    std::string why;
    std::optional<BaselineRecord> record = loadBaseline(stateDir_, why);
    if (!record) {
        logger()->warn("no baseline yet ({}): results will be no_baseline until one is captured", why);
        return;
    }
    const std::string calibration = parts_.chain->calibrationSha256();
    if (record->calibrationSha256 != calibration) {
        logger()->error("the stored baseline was taken with calibration {} but the camera is now calibrated as {}: "
                        "capture a new baseline",
                        record->calibrationSha256, calibration);
        return;
    }
    // Moved in: the stored images are not needed again, and the chain lets them go once rectified.
    // A record kept without a noise draw has its noise read off its image.
    const ChainResult accepted = parts_.chain->setBaseline(std::move(record->pair), std::move(record->noise));
    if (accepted.status != ChainResult::Status::Ok) {
        logger()->error("the stored baseline was refused by the volume chain: {}", accepted.reason);
        return;
    }
    std::lock_guard lock(mutex_);
    baselineInfo_ = {{"time", formatIsoUtc(record->time)}, {"calibration_sha256", record->calibrationSha256}};
    logger()->info("baseline of {} loaded", formatIsoUtc(record->time));
}

void Daemon::requestStop() {
    stop_ = true;
    std::lock_guard lock(mutex_);
    wake_.notify_all();
}

void Daemon::requestMeasure() {
    std::lock_guard lock(mutex_);
    requests_.measure = true;
    wake_.notify_all();
}

void Daemon::requestBaseline(std::string who) {
    std::lock_guard lock(mutex_);
    requests_.baseline = true;
    requests_.baselineBy = std::move(who);
    wake_.notify_all();
}

void Daemon::requestBaselineRestore(std::string who) {
    std::lock_guard lock(mutex_);
    requests_.baselineRestore = true;
    requests_.restoreBy = std::move(who);
    wake_.notify_all();
}

void Daemon::requestAlarmReset() {
    std::lock_guard lock(mutex_);
    requests_.alarmReset = true;
    wake_.notify_all();
}

void Daemon::requestReload() {
    std::lock_guard lock(mutex_);
    requests_.reload = true;
    wake_.notify_all();
}

void Daemon::setReadyStatus(std::string status) {
    std::lock_guard lock(mutex_);
    readyStatus_ = std::move(status);
}

Daemon::Requests Daemon::takeRequests() {
    std::lock_guard lock(mutex_);
    return std::exchange(requests_, Requests{});
}

void Daemon::waitUntil(TimePoint deadline) {
    std::unique_lock lock(mutex_);
    const bool pending = requests_.measure || requests_.baseline || requests_.baselineRestore ||
                         requests_.alarmReset || requests_.reload;
    if (pending || stopping()) {
        return;
    }
    clock_.waitUntil(lock, wake_, deadline);
}

void Daemon::progress() {
    if (!notifier_) return;
    if (!ready_) {
        // Before READY=1 systemd's start timeout runs, not the watchdog: each stage asks for
        // another allowance. Not the notifier's watchdog interval: in front of the Modbus
        // heartbeat that is 2 s, shorter than a stage.
        notifier_->notify("EXTEND_TIMEOUT_USEC=" + std::to_string(kStartStageAllowance.count()));
    } else if (notifier_->watchdogInterval()) {
        notifier_->notify("WATCHDOG=1");
    }
}

void Daemon::attachChain() {
    parts_.chain->onProgress([this] { progress(); });
}

void Daemon::run() {
    loop(std::nullopt);
}

void Daemon::runUntil(TimePoint end) {
    loop(end);
}

void Daemon::loop(std::optional<TimePoint> end) {
    if (notifier_) {
        std::lock_guard lock(mutex_);
        notifier_->notify("READY=1" + (readyStatus_.empty() ? std::string() : "\nSTATUS=" + readyStatus_));
        ready_ = true;
    }
    if (!scheduled_) {
        // The first cycle runs at once; the schedule then persists across run/runUntil calls.
        const TimePoint start = clock_.now();
        std::lock_guard lock(mutex_);
        nextCycle_ = start;
        nextCheck_ = start + std::chrono::seconds(config_.daemon.cameraCheckS);
        scheduled_ = true;
    }
    TimePoint& nextCheck = nextCheck_;
    while (!stopping()) {
        const Requests requests = takeRequests();
        if (requests.reload) reload();
        if (requests.alarmReset) resetAlarm();
        if (requests.baselineRestore) restorePreviousBaseline(requests.restoreBy);
        if (requests.baseline) captureBaseline(requests.baselineBy);
        const TimePoint now = clock_.now();
        if (end && now >= *end) {
            break;
        }
        TimePoint nextCycle;
        {
            std::lock_guard lock(mutex_);
            nextCycle = nextCycle_;
        }
        if (requests.measure || now >= nextCycle) {
            runCycle();
            if (now >= nextCycle) {
                // A fixed cadence; after a long stall (suspend, clock step) start afresh from now.
                const auto interval = std::chrono::seconds(config_.daemon.intervalS);
                nextCycle = nextCycle + interval > now ? nextCycle + interval : now + interval;
                std::lock_guard lock(mutex_);
                nextCycle_ = nextCycle;
            }
        }
        if (clock_.now() >= nextCheck) {
            completeParts();
            checkCamera();
            nextCheck = clock_.now() + std::chrono::seconds(config_.daemon.cameraCheckS);
        }
        if (faultIfUnmeasured(clock_.now())) {
            republishAlarm();
        }
        progress();
        TimePoint deadline = std::min(nextCycle, nextCheck);
        if (lastOk_ && !alarm_.faulted()) {
            deadline = std::min(deadline, *lastOk_ + std::chrono::seconds(config::maxRefusedS(config_.daemon)));
        }
        if (end) deadline = std::min(deadline, *end);
        if (notifier_ && notifier_->watchdogInterval()) {
            deadline = std::min(deadline, clock_.now() + std::chrono::duration_cast<TimePoint::duration>(
                                                               *notifier_->watchdogInterval() / 2));
        }
        waitUntil(deadline);
    }
    if (notifier_) {
        notifier_->notify("STOPPING=1");
    }
}

std::optional<CycleResult> Daemon::runOnce() {
    return runCycle();
}

std::optional<CycleResult> Daemon::runCycle() {
    if (const std::string missing = missingParts(); !missing.empty()) {
        // Nothing can be measured or signalled as it should: a fault that says what to do.
        alarm_.fault(missing);
        CycleResult r;
        r.time = clock_.now();
        r.status = CycleStatus::Fault;
        r.reason = missing;
        std::string detail;
        r.camera = parts_.source->health(detail);
        logger()->warn("fault: {}", missing);
        return publish(std::move(r), {}, true);
    }
    std::optional<CycleOutcome> outcome = runMeasurementCycle(
        *parts_.source, *parts_.chain, config_.daemon, clock_.now(), [this] { return stopping(); },
        [this] { progress(); });
    if (!outcome) {
        logger()->info("measurement cycle abandoned: stopping");
        return std::nullopt;
    }
    CycleResult& r = outcome->result;
    switch (r.status) {
        case CycleStatus::Ok:
            alarm_.measured({*r.volumeMm3, *r.uncertaintyMm3, *r.meanThicknessMm, *r.meanThicknessUncertaintyMm},
                            r.time);
            lastOk_ = r.time;
            break;
        // The gate said no: nothing was measured, so nothing may lower the level; only its age
        // (max_refused_s) can raise it to fault.
        case CycleStatus::Refused: faultIfUnmeasured(r.time); break;
        case CycleStatus::NoBaseline: alarm_.fault("no baseline"); break;
        case CycleStatus::Fault: alarm_.fault(r.reason); break;
    }
    {
        std::lock_guard lock(mutex_);
        camera_ = r.camera;
        cameraDetail_ = r.status == CycleStatus::Fault ? r.reason : "";
    }
    if (r.status == CycleStatus::Ok) {
        logger()->info("volume {:.0f} ± {:.0f} mm³, alarm {}", *r.volumeMm3, *r.uncertaintyMm3,
                       alarm::toString(alarm_.level()));
    } else {
        logger()->warn("{}: {}", toString(r.status), r.reason);
    }
    return publish(std::move(r), outcome->pictures, true);
}

void Daemon::checkCamera() {
    std::string detail;
    const CameraState state = parts_.source->health(detail);
    CameraState previous;
    {
        std::lock_guard lock(mutex_);
        previous = camera_;
        camera_ = state;
        cameraDetail_ = detail;
    }
    if (state == CameraState::Offline && previous != CameraState::Offline) {
        logger()->error("camera offline: {}", detail);
        alarm_.fault("camera offline: " + detail);
        CycleResult r;
        r.time = clock_.now();
        r.status = CycleStatus::Fault;
        r.reason = "camera offline: " + detail;
        r.camera = state;
        publish(std::move(r), {}, false);
    } else if (state != CameraState::Offline && previous == CameraState::Offline) {
        logger()->info("camera back: measuring now");
        std::lock_guard lock(mutex_);
        requests_.measure = true;
    }
}

void Daemon::captureBaseline(const std::string& who) {
    logger()->info("baseline capture requested by {}", who);
    if (!parts_.chain) {
        const std::string reason = "no baseline without a calibration: " + missingParts();
        logger()->error("baseline capture failed: {}", reason);
        std::lock_guard lock(mutex_);
        lastBaselineCapture_ = {{"time", formatIsoUtc(clock_.now())}, {"ok", false}, {"reason", reason},
                                {"requested_by", who}};
        return;
    }
    BaselineCapture capture = captureBaselinePair(*parts_.source, *parts_.chain, config_.daemon,
                                                  [this] { return stopping(); }, [this] { progress(); });
    const TimePoint time = clock_.now();
    nlohmann::json outcome = {{"time", formatIsoUtc(time)}, {"ok", capture.ok}};
    if (capture.ok) {
        BaselineRecord record{time, parts_.chain->calibrationSha256(), std::move(capture.pair), who, std::move(capture.noise)};
        std::string error;
        if (saveBaseline(stateDir_, record, error)) {
            logger()->info("baseline captured and stored (requested by {}); the previous one is kept, "
                           "`icewatch baseline restore` or POST /v1/baseline/restore goes back to it", who);
            std::lock_guard lock(mutex_);
            baselineInfo_ = {{"time", formatIsoUtc(time)},
                             {"calibration_sha256", record.calibrationSha256},
                             {"requested_by", who}};
            requests_.measure = true;  // the next result should be against the new reference
        } else {
            // The chain now holds a baseline that a restart would not find: say so loudly.
            logger()->error("baseline in use but not stored: {}", error);
            outcome["ok"] = false;
            outcome["reason"] = error;
        }
    } else {
        logger()->error("baseline capture failed: {}", capture.reason);
        outcome["reason"] = capture.reason;
    }
    outcome["requested_by"] = who;
    std::lock_guard lock(mutex_);
    lastBaselineCapture_ = std::move(outcome);
}

void Daemon::restorePreviousBaseline(const std::string& who) {
    std::string error;
    if (!restoreBaseline(stateDir_, error)) {
        logger()->error("baseline restore requested by {} failed: {}", who, error);
        std::lock_guard lock(mutex_);
        lastBaselineCapture_ = {{"time", formatIsoUtc(clock_.now())}, {"ok", false}, {"restore", true},
                                {"reason", error}, {"requested_by", who}};
        return;
    }
    logger()->info("previous baseline restored (requested by {})", who);
    {
        std::lock_guard lock(mutex_);
        baselineInfo_ = nullptr;
        lastBaselineCapture_ = {{"time", formatIsoUtc(clock_.now())}, {"ok", true}, {"restore", true},
                                {"requested_by", who}};
        requests_.measure = true;
    }
    loadStoredBaseline();
}

void Daemon::resetAlarm() {
    const alarm::AlarmLevel before = alarm_.level();
    const alarm::AlarmLevel after = alarm_.reset(clock_.now());
    logger()->info("alarm reset: {} -> {}", alarm::toString(before), alarm::toString(after));
    republishAlarm();
}

bool Daemon::faultIfUnmeasured(TimePoint now) {
    if (alarm_.faulted()) return false;  // already fault, with its own reason
    const int limitS = config::maxRefusedS(config_.daemon);
    if (lastOk_ && now - *lastOk_ < std::chrono::seconds(limitS)) return false;
    const std::string reason = "no ok result since " + (lastOk_ ? formatIsoUtc(*lastOk_) : std::string("the start")) +
                               " (daemon.max_refused_s " + std::to_string(limitS) + " s): nothing measured is not no ice";
    logger()->error("{}; fault until a measurement succeeds", reason);
    alarm_.fault(reason);
    return true;
}

void Daemon::republishAlarm() {
    const alarm::AlarmLevel level = alarm_.level();
    if (parts_.outputs && !parts_.outputs->show(level)) {
        logger()->error("the alarm outputs could not all be driven");
    }
    std::lock_guard lock(mutex_);
    if (latest_) {
        (*latest_)["alarm"] = alarm::toString(level);
        (*latest_)["alarm_reason"] = alarm_.faulted() ? nlohmann::json(alarm_.faultReason()) : nlohmann::json(nullptr);
        if (!writeFileAtomically(stateDir_ / "latest.json", latest_->dump(2) + "\n")) {
            logger()->error("cannot write {}", (stateDir_ / "latest.json").string());
        }
        if (sink_) sink_->published({*latest_, false, alarm_.latched()});
    }
}

void Daemon::reload() {
    completeParts();  // SIGHUP after installing the calibration: no need to wait for a check
    if (options_.configFile.empty()) {
        logger()->warn("reload requested but the daemon was not started from a configuration file");
        return;
    }
    config::Config next;
    std::string sha;
    std::string failure;
    // Whatever the file holds, the service goes on with what it has: no exception leaves here.
    try {
        next = config::loadConfig(options_.configFile);
        sha = sha256OfFile(options_.configFile).value_or("");
    } catch (const std::exception& e) {
        failure = e.what();
    } catch (...) {
        failure = "unknown error";
    }
    if (!failure.empty()) {
        logger()->error("configuration reload failed, keeping the previous configuration: {}", failure);
        std::lock_guard lock(mutex_);
        ++reloads_;
        ++failedReloads_;
        lastReloadError_ = failure;
        return;
    }
    next.http.tokenFile = config_.http.tokenFile;  // a restart-only setting, like the address
    HttpToken token = resolveHttpToken(next.http, /*create=*/true);
    for (const auto& section : restartOnlyChanges(config_, next)) {
        logger()->warn("configuration reload: {} changed; that takes effect at the next restart", section);
    }
    alarm_.setConfig(next.alarm);
    log::setLevel(next.log.level);
    std::lock_guard lock(mutex_);
    // Keep what only a restart may change; take the rest.
    next.camera = config_.camera;
    next.gpio = config_.gpio;
    next.http.enabled = config_.http.enabled;
    next.http.address = config_.http.address;
    next.http.port = config_.http.port;
    next.daemon.stateDir = config_.daemon.stateDir;
    next.calibration = config_.calibration;
    config_ = std::move(next);
    token_ = std::move(token);
    options_.configSha256 = sha;
    ++reloads_;
    lastReloadError_.clear();
    logger()->info("configuration reloaded from {}", options_.configFile.string());
}

CycleResult Daemon::publish(CycleResult result, const ChainPictures& pictures, bool toHistory) {
    result.alarm = alarm_.level();
    result.alarmReason = alarm_.faulted() ? alarm_.faultReason() : "";
    result.lastOk = lastOk_;
    result.version = options_.version;
    result.configSha256 = options_.configSha256;
    // The history first, so that latest.json can say whether it was written.
    std::string historyFault;
    if (toHistory && !history_.append(result)) {
        historyFault = "cannot write the history " + history_.file().string();
    }
    if (toHistory) {
        history_.pruneOlderThan(result.time - std::chrono::hours(24) * config_.history.retentionDays);
    }
    nlohmann::json doc = toJson(result);
    doc["storage_fault"] = historyFault.empty() ? nlohmann::json(nullptr) : nlohmann::json(historyFault);
    std::string latestFault;
    if (!writeFileAtomically(stateDir_ / "latest.json", doc.dump(2) + "\n")) {
        latestFault = "cannot write " + (stateDir_ / "latest.json").string() + ": " + std::strerror(errno);
        logger()->error("{}", latestFault);
        // Only the served copy can say it: the file on disk is the old one.
        doc["storage_fault"] = latestFault + (historyFault.empty() ? "" : "; " + historyFault);
    }
    const cv::Mat* images[] = {&pictures.left, &pictures.disparity, &pictures.thickness};
    for (std::size_t i = 0; i < kPictureNames.size(); ++i) {
        std::vector<uchar> png;
        if (images[i]->empty() || !cv::imencode(".png", *images[i], png)) continue;
        const auto path = stateDir_ / "images" / (kPictureNames[i] + ".png");
        if (!writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()),
                                 Durability::AtomicOnly)) {
            logger()->error("cannot write {}", path.string());
        }
    }
    if (parts_.outputs && !parts_.outputs->show(result.alarm)) {
        logger()->error("the alarm outputs could not all be driven");
    }
    std::lock_guard lock(mutex_);
    latest_ = doc;
    storageFault_ = doc["storage_fault"].is_string() ? doc["storage_fault"].get<std::string>() : std::string();
    latestWriteFailed_ = !latestFault.empty();
    if (sink_) sink_->published({doc, true, alarm_.latched()});
    return result;
}

std::optional<nlohmann::json> Daemon::latest() const {
    std::lock_guard lock(mutex_);
    if (!latest_) {
        return std::nullopt;
    }
    return withStaleness(*latest_, clock_.now(), config_.daemon);
}

alarm::AlarmLevel Daemon::alarmLevel() const {
    std::lock_guard lock(mutex_);
    if (!latest_) return alarm::AlarmLevel::Fault;
    const std::string level = textOf(*latest_, "alarm", "fault");
    for (auto l : {alarm::AlarmLevel::None, alarm::AlarmLevel::Warning, alarm::AlarmLevel::Alarm}) {
        if (level == alarm::toString(l)) return l;
    }
    return alarm::AlarmLevel::Fault;
}

std::optional<std::string> Daemon::iceShown() const {
    std::lock_guard lock(mutex_);
    const std::string level = latest_ ? textOf(*latest_, "alarm", "fault") : "fault";
    if (level == alarm::toString(alarm::AlarmLevel::Warning) || level == alarm::toString(alarm::AlarmLevel::Alarm)) {
        return "alarm level " + level;
    }
    return std::nullopt;
}

nlohmann::json Daemon::health() const {
    std::lock_guard lock(mutex_);
    const std::string alarmText = latest_ ? textOf(*latest_, "alarm", "fault") : "fault";
    const nlohmann::json served = latest_ ? withStaleness(*latest_, clock_.now(), config_.daemon) : nlohmann::json();
    const bool stale = latest_ ? served["stale"].get<bool>() : true;
    const std::string historyRecovery = history_.recovery();
    // What a person reading the 503 needs to know, most fundamental first.
    nlohmann::json reasons = nlohmann::json::array();
    for (const std::string* missing : {&chainMissing_, &outputsMissing_}) {
        if (!missing->empty()) reasons.push_back(*missing);
    }
    if (!latest_) {
        reasons.push_back("no result yet");
    } else if (const std::string why = textOf(*latest_, "alarm_reason", textOf(*latest_, "reason", "unknown"));
               alarmText == "fault" && why != chainMissing_ && why != outputsMissing_ &&
               why != chainMissing_ + "; " + outputsMissing_) {
        reasons.push_back("alarm level fault: " + why);
    }
    if (latest_ && stale) {
        reasons.push_back("stale since " + textOf(served, "stale_since", "?") + " (latest ok result " +
                          textOf(*latest_, "last_ok", "none") + ")");
    }
    if (camera_ == CameraState::Offline) reasons.push_back("camera offline: " + cameraDetail_);
    if (latestWriteFailed_) reasons.push_back(storageFault_);
    std::string status = "ok";
    if (alarmText == "fault" || camera_ == CameraState::Offline || stale || latestWriteFailed_ ||
        !chainMissing_.empty() || !outputsMissing_.empty()) {
        status = "fault";
    } else if (camera_ == CameraState::Degraded || (latest_ && textOf(*latest_, "status", "") != "ok") ||
               !storageFault_.empty() || !historyRecovery.empty()) {
        status = "degraded";
    }
    const auto orNull = [](const std::string& text) {
        return text.empty() ? nlohmann::json(nullptr) : nlohmann::json(text);
    };
    return {
        {"status", status},
        {"reasons", reasons},
        {"alarm", alarmText},
        {"camera", toString(camera_)},
        {"camera_detail", cameraDetail_.empty() ? nlohmann::json(nullptr) : nlohmann::json(cameraDetail_)},
        {"last_result", latest_ ? orNull(textOf(*latest_, "time", "")) : nlohmann::json(nullptr)},
        {"last_status", latest_ ? orNull(textOf(*latest_, "status", "")) : nlohmann::json(nullptr)},
        {"storage_fault", orNull(storageFault_)},
        {"history_recovery", orNull(historyRecovery)},
        {"http_token", token_.value.empty() ? nlohmann::json(token_.problem) : nlohmann::json("set")},
        {"stale", stale},
        {"next_cycle", formatIsoUtc(nextCycle_)},
        {"interval_s", config_.daemon.intervalS},
        {"baseline", baselineInfo_},
        {"last_baseline_capture", lastBaselineCapture_},
        {"config_file", options_.configFile.string()},
        {"config_sha256", options_.configSha256},
        {"reloads",
         {{"count", reloads_},
          {"failed", failedReloads_},
          {"last_error", lastReloadError_.empty() ? nlohmann::json(nullptr) : nlohmann::json(lastReloadError_)}}},
        {"version", options_.version},
        {"state_dir", stateDir_.string()},
    };
}

std::vector<nlohmann::json> Daemon::history(TimePoint since, int limit) const {
    return history_.since(since, limit);
}

std::optional<std::string> Daemon::picture(const std::string& name) const {
    if (std::find(kPictureNames.begin(), kPictureNames.end(), name) == kPictureNames.end()) {
        return std::nullopt;
    }
    std::ifstream in(stateDir_ / "images" / (name + ".png"), std::ios::binary);
    if (!in) {
        return std::nullopt;
    }
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

HttpToken Daemon::token() const {
    std::lock_guard lock(mutex_);
    return token_;
}

}  // namespace icewatch::daemon
