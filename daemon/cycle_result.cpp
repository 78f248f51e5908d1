// The result document. Every consumer (latest.json, history rows, the HTTP API, `icewatch status`)
// goes through toJson so the fields mean the same everywhere. Absent figures are null, never 0:
// zero is a measurement ("no ice"), null is "not measured".
#include "daemon/cycle_result.hpp"

#include <algorithm>

#include "daemon/iso_time.hpp"

namespace icewatch::daemon {

const char* toString(CameraState state) {
    switch (state) {
        case CameraState::Ok: return "ok";
        case CameraState::Offline: return "offline";
        case CameraState::Degraded: return "degraded";
    }
    return "offline";
}

const char* toString(CycleStatus status) {
    switch (status) {
        case CycleStatus::Ok: return "ok";
        case CycleStatus::Refused: return "refused";
        case CycleStatus::NoBaseline: return "no_baseline";
        case CycleStatus::Fault: return "fault";
    }
    return "fault";
}

namespace {
nlohmann::json optionalNumber(const std::optional<double>& value) {
    return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}
}  // namespace

nlohmann::json toJson(const CycleResult& r) {
    nlohmann::json flags = nlohmann::json::array();
    for (const auto& f : r.quality) {
        flags.push_back({{"flag", f.flag}, {"reason", f.reason}});
    }
    nlohmann::json timings = nlohmann::json::object();
    for (const auto& [stage, ms] : r.timingsMs) {
        timings[stage] = ms;
    }
    return {
        {"schema", kResultSchema},
        {"time", formatIsoUtc(r.time)},
        {"status", toString(r.status)},
        {"reason", r.reason.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.reason)},
        {"volume_mm3", optionalNumber(r.volumeMm3)},
        {"uncertainty_mm3", optionalNumber(r.uncertaintyMm3)},
        {"mean_thickness_mm", optionalNumber(r.meanThicknessMm)},
        {"mean_thickness_uncertainty_mm", optionalNumber(r.meanThicknessUncertaintyMm)},
        {"max_thickness_mm", optionalNumber(r.maxThicknessMm)},
        {"ice_area_mm2", optionalNumber(r.iceAreaMm2)},
        {"beyond_outline_mm3", optionalNumber(r.beyondOutlineMm3)},
        {"valid_percent", optionalNumber(r.validPercent)},
        {"alarm", alarm::toString(r.alarm)},
        {"alarm_reason", r.alarmReason.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.alarmReason)},
        {"last_ok", r.lastOk ? nlohmann::json(formatIsoUtc(*r.lastOk)) : nlohmann::json(nullptr)},
        {"camera", toString(r.camera)},
        {"quality",
         {{"frames_grabbed", r.framesGrabbed},
          {"frames_healthy", r.framesHealthy},
          {"frames_measured", r.framesMeasured},
          {"flags", flags}}},
        {"timings_ms", timings},
        {"version", r.version},
        {"config_sha256", r.configSha256},
    };
}

nlohmann::json withStaleness(nlohmann::json document, std::chrono::system_clock::time_point now,
                             const config::DaemonConfig& config) {
    using std::chrono::seconds;
    const auto timeOf = [&document](const char* key) -> std::optional<std::chrono::system_clock::time_point> {
        if (!document.contains(key) || !document[key].is_string()) return std::nullopt;
        return parseIsoUtc(document[key].get<std::string>());
    };
    const auto time = timeOf("time");
    const auto lastOk = timeOf("last_ok");
    std::optional<std::chrono::system_clock::time_point> since;
    if (time) {
        const auto noNews = *time + seconds(2 * static_cast<long long>(config.intervalS));
        if (now > noNews) since = noNews;
    }
    if (lastOk) {
        // Never an ok result: nothing shown can be old, and the level is fault anyway.
        const auto unmeasured = *lastOk + seconds(config::maxRefusedS(config));
        if (now >= unmeasured) since = since ? std::min(*since, unmeasured) : unmeasured;
    }
    document["stale"] = !time || since.has_value();
    document["stale_since"] = since ? nlohmann::json(formatIsoUtc(*since)) : nlohmann::json(nullptr);
    return document;
}

}  // namespace icewatch::daemon
