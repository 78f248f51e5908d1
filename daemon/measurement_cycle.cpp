// The measurement cycle. A single frame can be spoilt by a passing bird, a raindrop or a JPEG
// glitch, so each cycle grabs a burst and reports the median; how far the burst's volumes scatter
// is measurement noise the per-frame uncertainty does not see, so it is added to it in quadrature
// (as a robust standard deviation, 1.4826 x the median absolute deviation, expanded with the
// chain's coverage factor so both terms mean the same). The frames of one
// burst are seconds apart and strongly correlated, so the spread is not divided by sqrt(N).
//
// Outcome rules: any grab failure is a camera fault (the camera went away mid-cycle); a chain
// failure on every measurable frame is a measurement fault; fewer than min_frames measured frames
// otherwise is a refusal with the reasons; else a volume.
#include "daemon/measurement_cycle.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/health/image_health.hpp"

namespace icewatch::daemon {

namespace {

using Steady = std::chrono::steady_clock;

double msSince(Steady::time_point start) {
    return std::chrono::duration<double, std::milli>(Steady::now() - start).count();
}

struct Burst {
    std::vector<StereoPair> healthy;
    std::vector<double> sharpness;  // of each healthy pair (the weaker eye)
    std::vector<int> frameNumbers;  // 1-based, for messages
    int grabbed = 0;
    bool cameraFailed = false;
    std::string cameraError;
    std::vector<QualityFlag> flags;
    double grabMs = 0.0;
    double healthMs = 0.0;
};

// Grabs and health-checks a burst. Returns nullopt when cancelled.
std::optional<Burst> grabBurst(FrameSource& source, const config::DaemonConfig& config, const CancelCheck& cancelled,
                               const ProgressCallback& progress) {
    Burst burst;
    std::string error;
    if (!source.open(error)) {
        burst.cameraFailed = true;
        burst.cameraError = "camera offline: " + error;
        return burst;
    }
    for (int i = 1; i <= config.burstFrames; ++i) {
        if (cancelled()) {
            return std::nullopt;
        }
        const auto grabStart = Steady::now();
        std::optional<StereoPair> pair = source.grabFreshest(error);
        burst.grabMs += msSince(grabStart);
        progress();
        if (!pair) {
            burst.cameraFailed = true;
            burst.cameraError = "camera lost at frame " + std::to_string(i) + " of the burst: " + error;
            return burst;
        }
        ++burst.grabbed;
        const auto healthStart = Steady::now();
        bool healthy = true;
        double sharpness = 0.0;
        for (const auto& [eye, image] : {std::pair{"left", &pair->left}, std::pair{"right", &pair->right}}) {
            const health::ImageHealth h = health::checkImageHealth(*image, config.health);
            sharpness = eye == std::string("left") ? h.sharpness : std::min(sharpness, h.sharpness);
            for (const auto& p : h.problems) {
                burst.flags.push_back({p.flag, "frame " + std::to_string(i) + " " + eye + ": " + p.reason});
                healthy = false;
            }
        }
        burst.healthMs += msSince(healthStart);
        if (healthy) {
            burst.healthy.push_back(std::move(*pair));
            burst.sharpness.push_back(sharpness);
            burst.frameNumbers.push_back(i);
        }
    }
    return burst;
}

std::string flagSummary(const std::vector<QualityFlag>& flags) {
    std::map<std::string, int> counts;
    for (const auto& f : flags) ++counts[f.flag];
    std::string text;
    for (const auto& [flag, n] : counts) text += (text.empty() ? "" : ", ") + flag + " x" + std::to_string(n);
    return text;
}

}  // namespace

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::optional<CycleOutcome> runMeasurementCycle(FrameSource& source, MeasurementChain& chain,
                                                const config::DaemonConfig& config,
                                                std::chrono::system_clock::time_point time,
                                                const CancelCheck& cancelled, const ProgressCallback& progress) {
    const auto cycleStart = Steady::now();
    CycleOutcome outcome;
    CycleResult& r = outcome.result;
    r.time = time;
    std::string detail;
    if (!chain.hasBaseline()) {
        r.status = CycleStatus::NoBaseline;
        r.reason = "no baseline: capture one of the clean blade (icewatch baseline capture, POST /v1/baseline)";
        r.camera = source.health(detail);
        return outcome;
    }
    std::optional<Burst> burst = grabBurst(source, config, cancelled, progress);
    if (!burst) {
        return std::nullopt;
    }
    r.framesGrabbed = burst->grabbed;
    r.framesHealthy = static_cast<int>(burst->healthy.size());
    r.quality = burst->flags;
    r.timingsMs["grab"] = burst->grabMs;
    r.timingsMs["health"] = burst->healthMs;
    if (burst->cameraFailed) {
        r.status = CycleStatus::Fault;
        r.reason = burst->cameraError;
        r.camera = CameraState::Offline;
        return outcome;
    }
    r.camera = source.health(detail);
    if (r.camera == CameraState::Ok && r.framesHealthy < r.framesGrabbed) {
        r.camera = CameraState::Degraded;
    }

    std::vector<ChainResult> measured;
    std::vector<int> measuredFrames;
    int failed = 0;
    std::string firstRefusal, firstFailure;
    const auto measureStart = Steady::now();
    for (std::size_t i = 0; i < burst->healthy.size(); ++i) {
        if (cancelled()) {
            return std::nullopt;
        }
        ChainResult c = chain.estimate(burst->healthy[i]);
        progress();
        const std::string frame = "frame " + std::to_string(burst->frameNumbers[i]) + ": ";
        if (c.status == ChainResult::Status::Ok) {
            measured.push_back(std::move(c));
            measuredFrames.push_back(burst->frameNumbers[i]);
        } else if (c.status == ChainResult::Status::Refused) {
            r.quality.push_back({"refused", frame + c.reason});
            if (firstRefusal.empty()) firstRefusal = c.reason;
        } else {
            ++failed;
            r.quality.push_back({"failed", frame + c.reason});
            if (firstFailure.empty()) firstFailure = c.reason;
        }
    }
    r.timingsMs["measure"] = msSince(measureStart);
    r.framesMeasured = static_cast<int>(measured.size());

    if (r.framesMeasured < config.minFrames) {
        if (failed > 0 && failed == r.framesHealthy) {
            r.status = CycleStatus::Fault;
            r.reason = "measurement failed: " + firstFailure;
        } else {
            r.status = CycleStatus::Refused;
            if (r.framesHealthy < config.minFrames) {
                r.reason = std::to_string(r.framesHealthy) + " of " + std::to_string(r.framesGrabbed) +
                           " frames passed the image-health check (" + flagSummary(burst->flags) + "), " +
                           std::to_string(config.minFrames) + " needed";
            } else {
                r.reason = std::to_string(r.framesMeasured) + " of " + std::to_string(r.framesHealthy) +
                           " healthy frames measured, " + std::to_string(config.minFrames) + " needed: " +
                           (firstRefusal.empty() ? firstFailure : firstRefusal);
            }
        }
        r.timingsMs["total"] = msSince(cycleStart);
        return outcome;
    }

    std::vector<double> volumes, uncertainties, meanThickness, maxThickness, valid;
    for (const auto& c : measured) {
        volumes.push_back(c.volumeMm3);
        uncertainties.push_back(c.uncertaintyMm3);
        meanThickness.push_back(c.meanThicknessMm);
        maxThickness.push_back(c.maxThicknessMm);
        valid.push_back(c.validPercent);
    }
    const double volume = median(volumes);
    std::vector<double> deviations;
    for (double v : volumes) deviations.push_back(std::abs(v - volume));
    const double spread = measured.front().coverageFactor * 1.4826 * median(deviations);
    const double frameUncertainty = median(uncertainties);
    r.status = CycleStatus::Ok;
    r.volumeMm3 = volume;
    r.uncertaintyMm3 = std::sqrt(frameUncertainty * frameUncertainty + spread * spread);
    r.meanThicknessMm = median(meanThickness);
    r.maxThicknessMm = median(maxThickness);
    r.validPercent = median(valid);
    // Pictures and per-stage timings of the frame nearest the median: one coherent example.
    std::size_t nearest = 0;
    for (std::size_t i = 1; i < measured.size(); ++i) {
        if (std::abs(volumes[i] - volume) < std::abs(volumes[nearest] - volume)) nearest = i;
    }
    for (const auto& [stage, ms] : measured[nearest].timingsMs) {
        r.timingsMs["chain_" + stage] = ms;
    }
    outcome.pictures = std::move(measured[nearest].pictures);
    r.timingsMs["total"] = msSince(cycleStart);
    return outcome;
}

BaselineCapture captureBaselinePair(FrameSource& source, MeasurementChain& chain, const config::DaemonConfig& config,
                                    const CancelCheck& cancelled, const ProgressCallback& progress) {
    BaselineCapture capture;
    std::optional<Burst> burst = grabBurst(source, config, cancelled, progress);
    if (!burst) {
        capture.reason = "cancelled";
        return capture;
    }
    if (burst->cameraFailed) {
        capture.reason = burst->cameraError;
        return capture;
    }
    if (burst->healthy.empty()) {
        capture.reason = "no frame of the burst passed the image-health check (" + flagSummary(burst->flags) + ")";
        return capture;
    }
    const auto sharpest = std::max_element(burst->sharpness.begin(), burst->sharpness.end()) - burst->sharpness.begin();
    StereoPair& pair = burst->healthy[static_cast<std::size_t>(sharpest)];
    const ChainResult accepted = chain.setBaseline(pair);
    if (accepted.status != ChainResult::Status::Ok) {
        capture.reason = "the volume chain refused the baseline: " + accepted.reason;
        return capture;
    }
    capture.ok = true;
    capture.pair = std::move(pair);
    return capture;
}

}  // namespace icewatch::daemon
