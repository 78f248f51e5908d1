// The measurement cycle. A parked blade and a fixed camera give many frames of one scene in a
// fraction of a second, so a cycle grabs a burst and measures its float average once: the sensor
// noise, and most of the JPEG and quantisation error, fall by the square root of the frames kept.
// Frames failing the image-health check, or that moved or changed against the others (a gust, a
// bird), are left out of the average and named in the quality flags.
//
// Outcome rules: any grab failure is a camera fault (the camera went away mid-cycle); fewer than
// min_frames usable frames is a refusal naming why; a chain failure is a measurement fault, its
// refusal a refusal; else a volume.
#include "daemon/measurement_cycle.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/common/side_by_side.hpp"
#include "core/volume/capture_average.hpp"

namespace icewatch::daemon {

namespace {

using Steady = std::chrono::steady_clock;

double msSince(Steady::time_point start) {
    return std::chrono::duration<double, std::milli>(Steady::now() - start).count();
}

// A burst is averaged as it is grabbed: each frame joins the sum and is let go, so the daemon's
// memory does not grow with the burst's length (capture_average.hpp).
struct Burst {
    volume::CaptureAccumulator average;
    int grabbed = 0;
    bool cameraFailed = false;
    std::string cameraError;
    double grabMs = 0.0;
    double averageMs = 0.0;  // checking and summing the frames, between the grabs
};

volume::CaptureAverageOptions averageOptions(const config::DaemonConfig& config) {
    volume::CaptureAverageOptions options;
    options.health = config.health;
    options.minFrames = config.minFrames;
    return options;
}

// Grabs a burst of `count` frames into its average. Returns nullopt when cancelled.
std::optional<Burst> grabBurst(FrameSource& source, int count, const config::DaemonConfig& config,
                               const CancelCheck& cancelled, const ProgressCallback& progress) {
    Burst burst;
    burst.average = volume::CaptureAccumulator(averageOptions(config));
    std::string error;
    if (!source.open(error)) {
        burst.cameraFailed = true;
        burst.cameraError = "camera offline: " + error;
        return burst;
    }
    for (int i = 1; i <= count; ++i) {
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
        const auto averageStart = Steady::now();
        burst.average.add(joinSideBySide(pair->left, pair->right), "frame " + std::to_string(i));
        burst.averageMs += msSince(averageStart);
    }
    return burst;
}

std::vector<QualityFlag> qualityFlags(const volume::AveragedCapture& capture) {
    std::vector<QualityFlag> flags;
    for (const auto& d : capture.dropped) flags.push_back({d.flag, d.reason});
    return flags;
}

}  // namespace

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
    std::optional<Burst> burst = grabBurst(source, config.burstFrames, config, cancelled, progress);
    if (!burst) {
        return std::nullopt;
    }
    r.framesGrabbed = burst->grabbed;
    r.timingsMs["grab"] = burst->grabMs;
    if (burst->cameraFailed) {
        r.status = CycleStatus::Fault;
        r.reason = burst->cameraError;
        r.camera = CameraState::Offline;
        return outcome;
    }
    const auto averageStart = Steady::now();
    volume::AveragedCapture capture = burst->average.finish();
    r.timingsMs["average"] = burst->averageMs + msSince(averageStart);
    r.framesHealthy = capture.framesHealthy;
    r.framesMeasured = capture.framesUsed;
    r.quality = qualityFlags(capture);
    r.camera = source.health(detail);
    if (r.camera == CameraState::Ok && r.framesHealthy < r.framesGrabbed) {
        r.camera = CameraState::Degraded;
    }
    if (capture.frame.empty()) {
        r.status = CycleStatus::Refused;
        r.reason = "the burst gave no capture: " + capture.reason;
        r.timingsMs["total"] = msSince(cycleStart);
        return outcome;
    }
    if (cancelled()) {
        return std::nullopt;
    }
    const auto measureStart = Steady::now();
    // The eyes as views of the average, which the chain then holds alone: it lets the capture go
    // once rectified, before the matcher takes its buffers (17 MB at 3840x1080).
    StereoPair eyes = sideBySideViews(capture.frame);
    capture.frame.release();
    StereoPair noise = capture.noise.empty() ? StereoPair{} : sideBySideViews(capture.noise);
    capture.noise.release();
    ChainResult c = chain.estimate(std::move(eyes), std::move(noise));
    progress();
    r.timingsMs["measure"] = msSince(measureStart);
    for (const auto& [stage, ms] : c.timingsMs) r.timingsMs["chain_" + stage] = ms;
    r.timingsMs["total"] = msSince(cycleStart);
    if (c.status == ChainResult::Status::Failed) {
        r.status = CycleStatus::Fault;
        r.reason = "measurement failed: " + c.reason;
        return outcome;
    }
    if (c.status == ChainResult::Status::Refused) {
        r.status = CycleStatus::Refused;
        r.reason = c.reason;
        outcome.pictures = std::move(c.pictures);
        return outcome;
    }
    r.status = CycleStatus::Ok;
    r.volumeMm3 = c.volumeMm3;
    r.uncertaintyMm3 = c.uncertaintyMm3;
    r.meanThicknessMm = c.meanThicknessMm;
    r.meanThicknessUncertaintyMm = c.meanThicknessUncertaintyMm;
    r.maxThicknessMm = c.maxThicknessMm;
    r.iceAreaMm2 = c.iceAreaMm2;
    r.beyondOutlineMm3 = c.beyondOutlineMm3;
    r.validPercent = c.validPercent;
    outcome.pictures = std::move(c.pictures);
    return outcome;
}

BaselineCapture captureBaselinePair(FrameSource& source, MeasurementChain& chain, const config::DaemonConfig& config,
                                    const CancelCheck& cancelled, const ProgressCallback& progress) {
    BaselineCapture capture;
    std::optional<Burst> burst = grabBurst(source, config.baselineFrames, config, cancelled, progress);
    if (!burst) {
        capture.reason = "cancelled";
        return capture;
    }
    if (burst->cameraFailed) {
        capture.reason = burst->cameraError;
        return capture;
    }
    const volume::AveragedCapture averaged = burst->average.finish();
    if (averaged.frame.empty()) {
        capture.reason = "the burst gave no clean capture: " + averaged.reason;
        return capture;
    }
    StereoPair pair = splitSideBySide(averaged.frame);
    StereoPair noise = averaged.noise.empty() ? StereoPair{} : splitSideBySide(averaged.noise);
    const ChainResult accepted = chain.setBaseline(pair, noise);
    if (accepted.status != ChainResult::Status::Ok) {
        capture.reason = "the volume chain refused the baseline: " + accepted.reason;
        return capture;
    }
    capture.ok = true;
    capture.pair = std::move(pair);
    capture.noise = std::move(noise);
    return capture;
}

}  // namespace icewatch::daemon
