#pragma once

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/alarm/alarm_state.hpp"
#include "core/config/config.hpp"
#include "daemon/frame_source.hpp"

namespace icewatch::daemon {

// Version of the latest.json / history document layout; bump when a field changes meaning (a field
// added, ice_area_mm2 and beyond_outline_mm3, changes none).
constexpr int kResultSchema = 1;

enum class CycleStatus {
    Ok,          // a volume
    Refused,     // the quality gate or the image-health check refused the burst (fog, night, ...)
    NoBaseline,  // no clean-blade reference for this calibration yet
    Fault,       // camera offline or the measurement failed
};

const char* toString(CycleStatus status);

struct QualityFlag {
    std::string flag;    // dark, saturated, blurred, low_contrast, refused, failed
    std::string reason;  // with the frame and the figures
};

// One published result: latest.json, a history row, GET /v1/latest.
struct CycleResult {
    std::chrono::system_clock::time_point time;
    CycleStatus status = CycleStatus::Fault;
    std::string reason;
    std::optional<double> volumeMm3;
    std::optional<double> uncertaintyMm3;
    std::optional<double> meanThicknessMm;
    std::optional<double> meanThicknessUncertaintyMm;
    std::optional<double> maxThicknessMm;
    std::optional<double> iceAreaMm2;        // where the thickness was integrated
    std::optional<double> beyondOutlineMm3;  // of the volume, ice standing out of the clean outline
    std::optional<double> validPercent;
    alarm::AlarmLevel alarm = alarm::AlarmLevel::Fault;
    std::string alarmReason;  // why the level is fault; empty otherwise
    // The latest ok result's time, this one's included: what "stale" and the max_refused_s fault
    // are judged by. nullopt: none since the state directory was made.
    std::optional<std::chrono::system_clock::time_point> lastOk;
    CameraState camera = CameraState::Offline;
    int framesGrabbed = 0;
    int framesHealthy = 0;
    int framesMeasured = 0;
    std::vector<QualityFlag> quality;
    std::map<std::string, double> timingsMs;
    std::string version;
    std::string configSha256;
};

// The document, without "stale" (that depends on when it is read).
nlohmann::json toJson(const CycleResult& result);

// Adds "stale" and "stale_since" as judged at `now`: stale once the result is older than two
// measurement intervals (the loop stopped publishing) or the latest ok result ("last_ok") is
// daemon.max_refused_s old or older (results keep coming, but none measured). stale_since: when
// that began, null when not stale.
nlohmann::json withStaleness(nlohmann::json document, std::chrono::system_clock::time_point now,
                             const config::DaemonConfig& config);

}  // namespace icewatch::daemon
