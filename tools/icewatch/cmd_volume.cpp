// icewatch volume: run the whole volume chain on a scene directory (calibration, baseline and
// current capture, optional outline) and print the result. The daemon calls the same chain.
#include <sys/resource.h>

#include <chrono>
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>

#include "core/common/error.hpp"
#include "core/config/config.hpp"
#include "core/common/side_by_side.hpp"
#include "core/pictures/debug_directory.hpp"
#include "core/stereo/disparity_io.hpp"
#include "core/volume/capture_average.hpp"
#include "core/volume/chain.hpp"
#include "core/volume/scene_files.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/scene_recordings.hpp"
#include "tools/icewatch/terminal.hpp"

namespace icewatch::cli {

namespace {

nlohmann::json timingsJson(const volume::Timings& timings) {
    nlohmann::json out = nlohmann::json::object();
    double total = 0;
    for (const auto& [stage, ms] : timings) {
        out[stage] = ms;
        total += ms;
    }
    out["total"] = total;
    return out;
}

// Peak resident memory of this process so far (getrusage: kilobytes on Linux).
double peakRssMb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

nlohmann::json regionJson(const volume::MatchRegion& region, cv::Size frame) {
    const cv::Rect box = region.empty() ? cv::Rect({0, 0}, frame) : region.box;
    return {{"box", {{"x", box.x}, {"y", box.y}, {"width", box.width}, {"height", box.height}}},
            {"full_frame", region.empty()},
            {"min_disparity", region.band.min},
            {"max_disparity", region.band.max}};
}

// The current capture's chain as the timings count it: its surface and the estimate.
double captureChainMs(const volume::Surface& current, const volume::VolumeResult& result) {
    double total = 0;
    for (const auto& [stage, ms] : current.timingsMs) total += ms;
    for (const auto& [stage, ms] : result.timingsMs) total += ms;
    return total;
}

// The whole chain once more on a scene's captures, with other parameters (the comparisons).
struct ChainRun {
    volume::Surface baseline, current;
    volume::VolumeResult result;
};

ChainRun runChain(const volume::SceneFiles& scene, const volume::Parameters& parameters,
                  const stereo::Parameters& stereoParameters) {
    volume::VolumeChain chain(scene.calibration, parameters, [] { return std::chrono::steady_clock::now(); },
                              stereoParameters);
    ChainRun run;
    run.baseline = chain.measureSurface(scene.before.frame, scene.before.noise);
    run.current = chain.measureSurface(scene.after.frame, run.baseline, scene.after.noise);
    run.result = chain.estimate(run.baseline, run.current);
    return run;
}

// One stage's time in a surface's measurement (0 when it did not run).
double stageMs(const volume::Surface& surface, const std::string& stage) {
    double total = 0;
    for (const auto& [name, ms] : surface.timingsMs)
        if (name == stage) total += ms;
    return total;
}

nlohmann::json captureJson(const volume::AveragedCapture& capture) {
    nlohmann::json dropped = nlohmann::json::array();
    for (const auto& d : capture.dropped) dropped.push_back(d.reason);
    return {{"frames_used", capture.framesUsed}, {"frames_dropped", dropped}};
}

// The registered motion as a rotation vector (degrees) and a translation (mm), current ->
// baseline in the baseline's left camera frame: the same form as a rendered scene's truth.json.
nlohmann::json registrationMotionJson(const volume::RigidTransform& motion) {
    cv::Vec3d rotation;
    cv::Rodrigues(motion.rotation, rotation);
    rotation *= 180.0 / CV_PI;
    return {{"rotation_vector_deg", {rotation[0], rotation[1], rotation[2]}},
            {"translation_mm", {motion.translation[0], motion.translation[1], motion.translation[2]}}};
}

}  // namespace

void addVolumeCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("volume", "estimate the ice volume of a scene directory (exit 1 when refused)");
    struct Options {
        std::string scene;
        std::string method;
        std::string stereoMethod;
        std::string config;
        std::string debugDir;
        bool json = false;
        bool force = false;
        bool compareFullFrame = false;
        bool compareSlanted = false;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--scene", o->scene, "directory with calibration.yaml, before.png or before/ (a recording), after.png or after/ [, roi.json]")
        ->required();
    cmd->add_option("--method", o->method, "integration: trapz (default) or sum")->check(CLI::IsMember({"trapz", "sum"}));
    cmd->add_option("--stereo-method", o->stereoMethod, "matcher: paper, adcensus or sgbm (default: configuration)");
    cmd->add_option("--config", o->config, "configuration file whose \"volume\" and \"stereo\" sections to use");
    cmd->add_option("--debug-dir", o->debugDir, "write left.png, disparity.png, thickness.png (refused too, with the reason), cloud.ply, both "
                    "captures' disparities as measured (disparity_baseline.pfm, disparity_current.pfm) and the "
                    "thickness where it lies in the current left eye (thickness_mm.pfm, NaN where none) here");
    cmd->add_flag("--json", o->json, "print the result as one JSON object");
    addForceFlag(*cmd, o->force);
    cmd->add_flag("--compare-full-frame", o->compareFullFrame,
                  "also measure the current capture over the whole frame and the full disparity range, and print "
                  "both times and their ratio (the peak memory then includes it)");
    cmd->add_flag("--compare-slanted", o->compareSlanted,
                  "also measure both captures with the slanted-window stage as it was before it was made fast (its "
                  "plain kernel over the whole matched box, every window fitted to its end), and print both times, "
                  "their ratio and that run's volume");
    cmd->callback([&run, o] {
        run = [o] {
            if (!o->debugDir.empty()) checkOutputDirectory(o->debugDir, o->force, "--debug-dir");
            config::Config configuration;
            if (!o->config.empty()) configuration = config::loadConfig(o->config);
            volume::Parameters parameters = configuration.volume;
            if (!o->method.empty()) {
                parameters.integration = o->method == "sum" ? volume::Integration::Sum : volume::Integration::Trapz;
            }
            if (!o->stereoMethod.empty()) {
                try {
                    parameters.stereoMethod = stereo::parseMethod(o->stereoMethod);
                } catch (const InvalidInput& e) {
                    throw Error(kExitUsage, std::string("--stereo-method: ") + e.what());
                }
            }
            volume::CaptureAverageOptions averaging;
            averaging.health = configuration.daemon.health;
            volume::SceneFiles scene = volume::loadSceneDirectory(o->scene, readCaptureRecording, averaging);
            if (!scene.unusable.empty()) {
                // Nothing to measure: refused like any capture the gate turns away, with the
                // frames' own reasons.
                if (o->json) {
                    const nlohmann::json out{{"status", "refused"},
                                             {"reason", scene.unusable},
                                             {"baseline_capture", captureJson(scene.before)},
                                             {"current_capture", captureJson(scene.after)}};
                    std::cout << out.dump() << "\n";
                } else {
                    std::cout << "refused: " << scene.unusable << "\n";
                }
                return static_cast<int>(kExitFailure);
            }
            if (scene.roi) {
                parameters.roiPolygon.clear();
                for (const auto& p : *scene.roi) {
                    parameters.roiPolygon.push_back(p.x);
                    parameters.roiPolygon.push_back(p.y);
                }
            }
            Progress progress("volume");
            volume::VolumeChain chain(scene.calibration, parameters, [] { return std::chrono::steady_clock::now(); },
                                      configuration.stereo);
            volume::AveragedCapture& before = scene.before;
            volume::AveragedCapture& after = scene.after;
            progress.show("measuring the baseline");
            // Each average (17 MB at 3840x1080) is moved in unless compared later: the chain frees
            // it once rectified (measureSurface), before the match, where the memory peaks.
            const bool compared = o->compareFullFrame || o->compareSlanted;
            cv::Mat beforeFrame = before.frame, beforeNoise = before.noise;
            if (!compared) {
                before.frame.release();
                before.noise.release();
            }
            const volume::Surface baseline = chain.measureSurface(std::move(beforeFrame), std::move(beforeNoise));
            progress.show("measuring the current capture");
            cv::Mat afterFrame = after.frame, afterNoise = after.noise;
            if (!compared) {
                after.frame.release();
                after.noise.release();
            }
            const volume::Surface current =
                chain.measureSurface(std::move(afterFrame), baseline, std::move(afterNoise));
            progress.show("estimating the ice");
            const volume::VolumeResult r = chain.estimate(baseline, current);
            const double rssMb = peakRssMb();
            if (!o->debugDir.empty()) {
                // A refusal too: that is when a person wants to look.
                const pictures::MeasurementPictures drawn =
                    pictures::drawMeasurement(current, r, parameters.maxDisparity, configuration.pictures);
                pictures::writeDebugDirectory(drawn, r, configuration.pictures, o->debugDir);
                // The matcher's own numbers, to hold against a rendered scene's true disparities.
                stereo::writePfm(std::filesystem::path(o->debugDir) / "disparity_baseline.pfm", baseline.disparity);
                stereo::writePfm(std::filesystem::path(o->debugDir) / "disparity_current.pfm", current.disparity);
            }
            progress.done();
            nlohmann::json timings = timingsJson(current.timingsMs);
            const nlohmann::json estimateTimings = timingsJson(r.timingsMs);
            for (const auto& [stage, ms] : estimateTimings.items()) {
                if (stage != "total") timings[stage] = ms;
            }
            // The chain per new capture: the current surface and the estimate (the daemon keeps
            // the baseline's surface); the baseline's own measurement is listed apart.
            timings["total"] = timings["total"].get<double>() + estimateTimings["total"].get<double>();
            timings["baseline_surface"] = timingsJson(baseline.timingsMs)["total"];
            nlohmann::json out{{"status", r.ok ? "ok" : "refused"},
                               {"stereo_method", stereo::methodName(parameters.stereoMethod)},
                               {"integration", parameters.integration == volume::Integration::Sum ? "sum" : "trapz"},
                               {"points_used", r.pointsUsed},
                               {"valid_percent", r.validPercent},
                               {"registration_mm", r.registrationMm},
                               {"registration_deg", r.registrationDeg},
                               {"registration_rms_mm", r.registrationRmsMm},
                               {"registration_motion", registrationMotionJson(r.registration)},
                               {"object_light", {{"shift", r.objectLightShift}, {"spread", r.objectLightSpread}}},
                               {"registration_source", r.registrationSource},
                               {"texture_inliers", r.textureInliers},
                               {"background_inliers", r.backgroundInliers},
                               {"unchanged_samples", r.unchangedSamples},
                               {"changed_samples", r.changedSamples},
                               {"registration_support_percent", r.supportSpanPercent},
                               {"outline_growth_mm", r.outlineGrowthMm},
                               {"outline_growth_stations", r.outlineGrowthStations},
                               {"outline_blur_px", r.blurPx},
                               {"faint_ice_percent", r.faintIcePercent},
                               {"image_contrast", {{"baseline", r.baselineContrast}, {"current", r.currentContrast}}},
                               {"baseline_capture", captureJson(before)},
                               {"current_capture", captureJson(after)},
                               {"timings_ms", timings},
                               {"matched_region", regionJson(current.matched, baseline.disparity.size())},
                               {"peak_rss_mb", rssMb}};
            if (o->compareFullFrame) {
                // The chain as it was: both captures over the whole frame, every disparity.
                volume::Parameters wholeFrame = parameters;
                wholeFrame.matchRegion = false;
                const ChainRun fullRun = runChain(scene, wholeFrame, configuration.stereo);
                const volume::Surface& full = fullRun.current;
                const volume::VolumeResult& fr = fullRun.result;
                const double regionMs = captureChainMs(current, r), fullMs = captureChainMs(full, fr);
                out["full_frame"] = {{"status", fr.ok ? "ok" : "refused"},
                                     {"volume_mm3", fr.ok ? fr.volumeMm3 : 0.0},
                                     {"capture_ms", fullMs},
                                     {"region_capture_ms", regionMs},
                                     {"speedup", regionMs > 0 ? fullMs / regionMs : 0.0},
                                     {"peak_rss_mb", peakRssMb()}};
            }
            if (o->compareSlanted) {
                // The same chain, its slanted windows as they were.
                volume::Parameters asBefore = parameters;
                asBefore.slantedWindowAsBefore = true;
                const ChainRun old = runChain(scene, asBefore, configuration.stereo);
                const volume::VolumeResult& orr = old.result;
                const double nowMs = stageMs(current, "slanted") + stageMs(baseline, "slanted");
                const double beforeMs = stageMs(old.current, "slanted") + stageMs(old.baseline, "slanted");
                out["slanted_before"] = {{"status", orr.ok ? "ok" : "refused"},
                                         {"volume_mm3", orr.ok ? orr.volumeMm3 : 0.0},
                                         {"slanted_ms", beforeMs},
                                         {"slanted_now_ms", nowMs},
                                         {"speedup", nowMs > 0 ? beforeMs / nowMs : 0.0}};
            }
            if (r.ok) {
                out["volume_mm3"] = r.volumeMm3;
                out["uncertainty_mm3"] = r.uncertaintyMm3;
                out["uncertainty_budget_mm3"] = {{"noise", r.budget.noiseMm3},
                                                 {"registration", r.budget.registrationMm3},
                                                 {"tracking", r.budget.trackingMm3},
                                                 {"push", r.budget.pushMm3},
                                                 {"bias", r.budget.biasMm3},
                                                 {"edge", r.budget.edgeMm3},
                                                 {"scale", r.budget.scaleMm3},
                                                 {"outline", r.budget.outlineMm3},
                                                 {"fattening", r.budget.fatteningMm3},
                                                 {"seen_through", r.budget.seenThroughMm3},
                                                 {"hidden", r.budget.hiddenMm3}};
                out["mean_thickness_mm"] = r.meanThicknessMm;
                out["mean_thickness_uncertainty_mm"] = r.meanThicknessUncertaintyMm;
                out["max_thickness_mm"] = r.maxThicknessMm;
                out["area_mm2"] = r.areaMm2;
                out["ice_area_mm2"] = r.iceAreaMm2;
                out["beyond_outline_mm3"] = r.beyondOutlineMm3;
                out["beyond_outline_area_mm2"] = r.beyondOutlineAreaMm2;
                out["seen_through_mm3"] = r.seenThroughMm3;
                out["glimpsed_through_mm3"] = r.glimpsedThroughMm3;
                out["ice_mask_percent"] = r.iceMaskPercent;
                out["outline_background_percent"] = r.outlineBackgroundPercent;
                out["matcher_push_px"] = r.matcherPushPx;
                out["matcher_push_sigma_px"] = r.matcherPushSigmaPx;
                out["filled_percent"] = r.filledPercent;
            } else {
                out["reason"] = r.reason;
            }
            if (o->json) {
                std::cout << out.dump() << "\n";
            } else if (r.ok) {
                std::cout << "ice volume " << r.volumeMm3 << " mm3 ± " << r.uncertaintyMm3 << " mm3 (mean thickness "
                          << r.meanThicknessMm << " mm, " << r.pointsUsed << " points, registration "
                          << r.registrationMm << " mm)\n";
            } else {
                std::cout << "refused: " << r.reason << "\n";
            }
            return r.ok ? 0 : static_cast<int>(kExitFailure);
        };
    });
}

}  // namespace icewatch::cli
