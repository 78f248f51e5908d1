// The configuration file: one JSON object with a section per subsystem. Sections are read by
// typed, range-checked readers (section.hpp); nothing outside this file knows the JSON layout.
#include "core/config/config.hpp"

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/config/json_text.hpp"
#include "core/config/scada_section.hpp"
#include "core/config/section.hpp"
#include "core/stereo/matcher.hpp"

namespace icewatch::config {

namespace {

void readLog(Section s, LogConfig& log) {
    s.readChoice("level", log.level, {"trace", "debug", "info", "warn", "error"});
    s.finish();
}

void readCamera(Section s, CameraConfig& camera) {
    s.read("device", camera.device);
    if (camera.device.empty()) {
        s.reject("device", "must not be empty");
    }
    s.readChoice("format", camera.format, {"mjpeg", "yuyv"});
    s.read("width", camera.width, 2, 16384);
    s.read("height", camera.height, 1, 16384);
    if (camera.width % 2 != 0) {
        s.reject("width", "must be even: the frame holds two equal eyes side by side");
    }
    s.read("fps", camera.fps, 1, 240);
    s.read("buffers", camera.buffers, 2, 32);
    s.read("frame_timeout_ms", camera.frameTimeoutMs, 100, 60000);
    s.read("reconnect_min_ms", camera.reconnectMinMs, 10, 600000);
    s.read("reconnect_max_ms", camera.reconnectMaxMs, 10, 3600000);
    if (camera.reconnectMaxMs < camera.reconnectMinMs) {
        s.reject("reconnect_max_ms", "must not be below reconnect_min_ms");
    }
    s.read("controls", camera.controls);
    s.finish();
}

void readCalibration(Section s, CalibrationConfig& calibration) {
    s.read("file", calibration.file);
    if (calibration.file.empty()) {
        s.reject("file", "must not be empty");
    }
    s.finish();
}

void readVolume(Section s, volume::Parameters& v) {
    std::string method = stereo::methodName(v.stereoMethod);
    s.readChoice("stereo_method", method, {"paper", "adcensus", "sgbm"});
    v.stereoMethod = stereo::parseMethod(method);
    s.read("max_disparity", v.maxDisparity, 16, 1024);
    s.read("roi_polygon", v.roiPolygon);
    if (!v.roiPolygon.empty() && (v.roiPolygon.size() % 2 != 0 || v.roiPolygon.size() < 6)) {
        s.reject("roi_polygon", "must be x, y pairs of at least 3 points (or empty to segment)");
    }
    s.read("edge_margin_px", v.edgeMarginPx, 0, 50);
    s.read("segmentation_band_mm", v.segmentationBandMm, 1.0, 5000.0);
    s.read("track_radius_px", v.trackRadiusPx, 4, 40);
    s.read("track_step_px", v.trackStepPx, 2, 100);
    s.read("track_search_px", v.trackSearchPx, 1, 64);
    s.read("min_evidence_samples", v.minEvidenceSamples, 6, 100000);
    s.read("background_band_mm", v.backgroundBandMm, 0.0, 10000.0);
    s.read("max_registration_mm", v.maxRegistrationMm, 0.1, 1000.0);
    s.read("min_support_span_percent", v.minSupportSpanPercent, 0.0, 100.0);
    s.read("max_object_alone_light_spread_percent", v.maxObjectAloneLightSpreadPercent, 0.0, 100.0);
    s.read("ice_mask_grow_px", v.iceMaskGrowPx, 0, 500);
    s.read("outline_growth_mm", v.outlineGrowthMm, 0.0, 500.0);
    s.read("outline_ice_min_mm", v.outlineIceMinMm, 0.1, 100.0);
    s.read("outline_footing_mm", v.outlineFootingMm, 0.0, 100.0);
    s.read("outline_standoff_mm", v.outlineStandoffMm, 0.0, 1000.0);
    s.read("outline_min_texture_grey", v.outlineMinTextureGrey, 0.0, 255.0);
    s.read("outline_min_correlation", v.outlineMinCorrelation, 0.0, 1.0);
    s.read("outline_min_contrast_grey", v.outlineMinContrastGrey, 0.0, 255.0);
    s.read("outline_fringe_px", v.outlineFringePx, 0, 200);
    s.read("outline_max_obliquity_deg", v.outlineMaxObliquityDeg, 0.0, 90.0);
    s.read("knn_k", v.knnK, 2, 100);
    s.read("knn_theta", v.knnTheta, 0.1, 20.0);
    s.read("grid_cell_mm", v.gridCellMm, 0.05, 100.0);
    std::string integration = v.integration == volume::Integration::Sum ? "sum" : "trapz";
    s.readChoice("integration", integration, {"trapz", "sum"});
    v.integration = integration == "sum" ? volume::Integration::Sum : volume::Integration::Trapz;
    s.read("max_thickness_mm", v.maxThicknessMm, 1.0, 2000.0);
    s.read("max_ice_thickness_mm", v.maxIceThicknessMm, 0.0, 2000.0);
    s.read("match_region", v.matchRegion);
    s.read("slanted_window", v.slantedWindow);
    s.read("slanted_window_radius_px", v.slantedWindowRadiusPx, 1, 32);
    s.read("slanted_window_max_sigma_px", v.slantedWindowMaxSigmaPx, 0.001, 1.0);
    s.read("occlusion_slope", v.occlusionSlope, 0.0, 1000.0);
    s.read("occlusion_step_mm", v.occlusionStepMm, 0.0, 1000.0);
    s.read("disparity_noise_px", v.disparityNoisePx, 0.0, 10.0);
    s.read("correlation_px", v.correlationPx, 1, 64);
    s.read("subpixel_bias_px", v.subpixelBiasPx, 0.0, 1.0);
    s.read("track_bias_px", v.trackBiasPx, 0.0, 1.0);
    s.read("edge_uncertainty_px", v.edgeUncertaintyPx, 0.0, 10.0);
    s.read("facing_fattening_px", v.facingFatteningPx, 0.0, 20.0);
    s.read("fattening_separable_step_px", v.fatteningSeparableStepPx, 0.0, 20.0);
    s.read("blur_fattening_per_px", v.blurFatteningPerPx, 0.0, 20.0);
    s.read("scale_uncertainty_percent", v.scaleUncertaintyPercent, 0.0, 50.0);
    s.read("coverage_factor", v.coverageFactor, 1.0, 5.0);
    s.read("min_valid_percent", v.minValidPercent, 0.0, 100.0);
    s.read("min_mean_grey", v.minMeanGrey, 0.0, 255.0);
    s.read("max_saturated_percent", v.maxSaturatedPercent, 0.0, 100.0);
    s.read("max_new_saturated_percent", v.maxNewSaturatedPercent, 0.0, 100.0);
    s.read("min_contrast", v.minContrast, 0.0, 255.0);
    s.read("min_contrast_object_motion", v.minContrastObjectMotion, 0.0, 255.0);
    s.read("min_points", v.minPoints, 10, 100000000);
    s.read("max_filled_percent", v.maxFilledPercent, 0.0, 100.0);
    s.finish();
}

void readStereo(Section s, stereo::Parameters& p) {
    s.read("impulse_threshold", p.impulseThreshold, 0, 255);
    s.read("impulse_rail_threshold", p.impulseRailThreshold, 0, 255);
    s.read("noise_smoothing_gain", p.noiseSmoothingGain, 0.0, 10.0);
    s.read("noise_grey_pass_range", p.noiseGreyPassRange, 0.0, 20.0);
    s.read("census_gradient_threshold", p.censusGradientThreshold, 0.0, 1000.0);
    s.read("census_alpha", p.censusAlpha, 0, 64);
    s.read("census_alpha_noise_gain", p.censusAlphaNoiseGain, 0.0, 10.0);
    s.read("canny_low_threshold", p.cannyLowThreshold, 0.0, 10000.0);
    s.read("canny_high_threshold", p.cannyHighThreshold, 0.0, 10000.0);
    if (p.cannyHighThreshold < p.cannyLowThreshold) {
        s.reject("canny_high_threshold", "must not be below canny_low_threshold");
    }
    s.read("harris_threshold", p.harrisThreshold, 0.0, 1.0);
    s.read("lambda_census", p.lambdaCensus, 0.01, 1000.0);
    s.read("lambda_ad", p.lambdaAd, 0.01, 1000.0);
    s.read("lambda_gradient", p.lambdaGradient, 0.01, 1000.0);
    s.read("mei_lambda_census", p.meiLambdaCensus, 0.01, 1000.0);
    s.read("mei_lambda_ad", p.meiLambdaAd, 0.01, 1000.0);
    s.read("cross_tau1", p.crossTau1, 1, 255);
    s.read("cross_tau2", p.crossTau2, 1, 255);
    s.read("cross_l1", p.crossL1, 1, 127);
    s.read("cross_l2", p.crossL2, 1, 127);
    if (p.crossTau2 > p.crossTau1) s.reject("cross_tau2", "must not exceed cross_tau1");
    if (p.crossL2 > p.crossL1) s.reject("cross_l2", "must not exceed cross_l1");
    s.read("cross_iterations", p.crossIterations, 0, 8);
    // Π2 <= 10 keeps the 16-bit sum of 8 scanline directions from saturating.
    s.read("scanline_pi1", p.scanlinePi1, 0.0, 10.0);
    s.read("scanline_pi2", p.scanlinePi2, 0.0, 10.0);
    if (p.scanlinePi2 < p.scanlinePi1) s.reject("scanline_pi2", "must not be below scanline_pi1");
    s.read("scanline_tau", p.scanlineTau, 0, 255);
    s.read("lr_max_difference", p.lrMaxDifference, 0, 16);
    s.read("right_view_aggregation", p.rightViewAggregation);
    s.read("right_view_scanline_directions", p.rightViewScanlineDirections, 4, 8);
    if (p.rightViewScanlineDirections != 4 && p.rightViewScanlineDirections != 8) {
        s.reject("right_view_scanline_directions", "must be 4 or 8");
    }
    s.read("voting_iterations", p.votingIterations, 0, 20);
    s.read("voting_min_count", p.votingMinCount, 0, 100000);
    s.read("voting_min_ratio", p.votingMinRatio, 0.0, 1.0);
    s.read("discontinuity_adjustment", p.discontinuityAdjustment);
    s.read("subpixel_intensity_refinement", p.subpixelIntensityRefinement);
    s.read("subpixel_window_radius", p.subpixelWindowRadius, 1, 7);
    s.read("subpixel_iterations", p.subpixelIterations, 1, 10);
    s.read("subpixel_max_change", p.subpixelMaxChange, 0.0, 2.0);
    s.read("median_filter", p.medianFilter);
    s.read("sgbm_block_size", p.sgbmBlockSize, 1, 11);
    if (p.sgbmBlockSize % 2 == 0) s.reject("sgbm_block_size", "must be odd");
    s.read("sgbm_fill_holes", p.sgbmFillHoles);
    s.finish();
}

void readHealth(Section s, ImageHealthConfig& health) {
    s.read("min_mean_level", health.minMeanLevel, 0.0, 255.0);
    s.read("max_saturated_percent", health.maxSaturatedPercent, 0.0, 100.0);
    s.read("min_sharpness", health.minSharpness, 0.0, 1e6);
    s.read("min_contrast", health.minContrast, 0.0, 255.0);
    s.finish();
}

void readDaemon(Section s, DaemonConfig& daemon) {
    s.read("interval_s", daemon.intervalS, 10, 86400);
    s.read("burst_frames", daemon.burstFrames, 1, 256);
    s.read("baseline_frames", daemon.baselineFrames, 1, 256);
    s.read("min_frames", daemon.minFrames, 1, 256);
    if (daemon.minFrames > daemon.burstFrames || daemon.minFrames > daemon.baselineFrames) {
        s.reject("min_frames", "must not exceed burst_frames or baseline_frames");
    }
    s.read("camera_check_s", daemon.cameraCheckS, 1, 3600);
    s.read("max_refused_s", daemon.maxRefusedS, 0, 7 * 86400);
    if (daemon.maxRefusedS != 0 && daemon.maxRefusedS < daemon.intervalS) {
        // Shorter than a cycle, every ok result would age into a fault before the next one came.
        s.fail("max_refused_s", "must be 0 (three intervals) or at least interval_s");
    }
    s.read("state_dir", daemon.stateDir);
    if (daemon.stateDir.empty()) {
        s.reject("state_dir", "must not be empty");
    }
    readHealth(s.child("health"), daemon.health);
    s.finish();
}

void readAlarm(Section s, AlarmConfig& alarm) {
    s.readChoice("metric", alarm.metric, {"volume_mm3", "mean_thickness_mm"});
    s.readChoice("judge", alarm.judge, {"estimate", "upper_bound"});
    s.read("warning_set", alarm.warningSet, 0.0, 1e12);
    s.read("warning_clear", alarm.warningClear, 0.0, 1e12);
    s.read("alarm_set", alarm.alarmSet, 0.0, 1e12);
    s.read("alarm_clear", alarm.alarmClear, 0.0, 1e12);
    if (alarm.warningClear >= alarm.warningSet) {
        s.reject("warning_clear", "must be below warning_set (hysteresis)");
    }
    if (alarm.alarmClear >= alarm.alarmSet) {
        s.reject("alarm_clear", "must be below alarm_set (hysteresis)");
    }
    if (alarm.alarmSet < alarm.warningSet) {
        s.reject("alarm_set", "must not be below warning_set");
    }
    s.read("warning_hold_s", alarm.warningHoldS, 0, 7 * 86400);
    s.read("alarm_hold_s", alarm.alarmHoldS, 0, 7 * 86400);
    s.read("latch", alarm.latch);
    s.finish();
}

void readGpio(Section s, GpioConfig& gpio) {
    s.read("chip", gpio.chip);
    if (gpio.chip.empty() || gpio.chip == "fake:") {
        s.reject("chip", "must name a chip, \"none\", \"fake\" or fake:FILE");
    }
    s.read("alarm_line", gpio.alarmLine, 0, 65535);
    s.read("healthy_line", gpio.healthyLine, 0, 65535);
    if (gpio.alarmLine == gpio.healthyLine) {
        s.reject("healthy_line", "must differ from alarm_line");
    }
    s.read("active_low", gpio.activeLow);
    s.read("consumer", gpio.consumer);
    if (gpio.consumer.empty() || gpio.consumer.size() > 31) {
        s.reject("consumer", "must be 1 to 31 characters (the kernel's label size)");
    }
    s.finish();
}

void readHttp(Section s, HttpConfig& http) {
    s.read("enabled", http.enabled);
    s.read("address", http.address);
    if (http.address.empty()) {
        s.reject("address", "must not be empty");
    }
    s.read("port", http.port, 0, 65535);
    s.read("token", http.token);
    const bool tokenFileGiven = s.has("token_file");
    s.read("token_file", http.tokenFile);
    if (http.tokenFile.empty()) {
        s.reject("token_file", "must not be empty");
    }
    // Any machine on the network could otherwise read the results; the operator must have chosen
    // where the credentials of the clients come from.
    if (http.enabled && !isLoopbackAddress(http.address) && http.token.empty() && !tokenFileGiven) {
        s.reject("address", "\"" + http.address +
                              "\" is reachable from other machines: set http.token or http.token_file "
                              "(or listen on 127.0.0.1 behind a reverse proxy)");
    }
    s.finish();
}

void readHistory(Section s, HistoryConfig& history) {
    s.read("retention_days", history.retentionDays, 1, 36500);
    s.finish();
}

void readPictures(Section s, pictures::PictureScale& scale) {
    s.read("max_thickness_mm", scale.maxThicknessMm, 0.1, 2000.0);
    s.finish();
}

}  // namespace

int maxRefusedS(const DaemonConfig& daemon) {
    return daemon.maxRefusedS > 0 ? daemon.maxRefusedS : 3 * daemon.intervalS;
}

bool isLoopbackAddress(const std::string& address) {
    return address == "localhost" || address == "::1" || address == "[::1]" || address.rfind("127.", 0) == 0;
}

namespace {

// Every problem is noted in `problems`; what could be read stands, the rest keeps its default.
Config readConfig(std::string_view text, const std::string& fileName, std::vector<std::string>& problems) {
    Config config;
    config.sourceFile = fileName;
    JsonText parsed = parseJsonText(text);
    if (!parsed.error.empty()) {
        problems.push_back(fileName + ": " + parsed.error);
        return config;
    }
    const nlohmann::json root = std::move(parsed.value);
    if (!root.is_object()) {
        problems.push_back(fileName + ": the top level must be a JSON object");
        return config;
    }
    Section top(root, fileName, "");
    top.collectProblems(problems);
    readLog(top.child("log"), config.log);
    readCamera(top.child("camera"), config.camera);
    readCalibration(top.child("calibration"), config.calibration);
    readVolume(top.child("volume"), config.volume);
    readStereo(top.child("stereo"), config.stereo);
    readDaemon(top.child("daemon"), config.daemon);
    readAlarm(top.child("alarm"), config.alarm);
    readGpio(top.child("gpio"), config.gpio);
    readHttp(top.child("http"), config.http);
    readHistory(top.child("history"), config.history);
    readPictures(top.child("pictures"), config.pictures);
    readScada(top.child("scada"), config.scada);
    top.finish();
    return config;
}

std::string joined(const std::vector<std::string>& problems) {
    std::string text;
    for (const auto& p : problems) text += (text.empty() ? "" : "\n") + p;
    return text;
}

// A relative path in a file means the file's own directory, wherever the program was started
// (systemd starts in /, a person in their home): the configuration and its calibration travel together.
void resolveAgainst(std::string& path, const std::filesystem::path& dir, std::string_view prefix = {}) {
    if (!path.starts_with(prefix)) return;
    const std::filesystem::path rest = path.substr(prefix.size());
    if (rest.empty() || rest.is_absolute()) return;
    path = std::string(prefix) + (dir / rest).lexically_normal().string();
}

void resolveRelativePaths(Config& config, const std::filesystem::path& dir) {
    if (dir.empty()) return;
    resolveAgainst(config.calibration.file, dir);
    resolveAgainst(config.daemon.stateDir, dir);
    resolveAgainst(config.http.tokenFile, dir);
    resolveAgainst(config.camera.device, dir, "fake:");
    if (config.gpio.chip != "fake") resolveAgainst(config.gpio.chip, dir, "fake:");
    resolveAgainst(config.scada.mqtt.passwordFile, dir);
    resolveAgainst(config.scada.mqtt.caFile, dir);
}

}  // namespace

Config parseConfig(std::string_view text, const std::string& fileName) {
    std::vector<std::string> problems;
    Config config = readConfig(text, fileName, problems);
    if (!problems.empty()) throw ConfigError(joined(problems));
    return config;
}

GpioConfig loadGpioSection(const std::filesystem::path& path, std::string& problem) {
    try {
        std::ifstream in(path, std::ios::binary);
        if (!in) {
            problem = path.string() + ": cannot read the configuration file";
            return {};
        }
        std::ostringstream text;
        text << in.rdbuf();
        JsonText parsed = parseJsonText(text.str());
        if (!parsed.error.empty()) {
            problem = path.string() + ": " + parsed.error;
            return {};
        }
        GpioConfig gpio;
        if (parsed.value.is_object() && parsed.value.contains("gpio")) {
            readGpio(Section(parsed.value["gpio"], path.string(), "gpio"), gpio);
        }
        return gpio;
    } catch (const std::exception& e) {
        problem = e.what();
        return {};
    }
}

ConfigCheck checkConfigFile(const std::filesystem::path& path) {
    ConfigCheck check;
    check.config.sourceFile = path.string();
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        check.problems.push_back(path.string() + ": cannot read the configuration file");
        return check;
    }
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) {
        check.problems.push_back(path.string() + ": error while reading the configuration file");
        return check;
    }
    check.config = readConfig(text.str(), path.string(), check.problems);
    resolveRelativePaths(check.config, path.parent_path());
    return check;
}

Config loadConfig(const std::filesystem::path& path) {
    ConfigCheck check = checkConfigFile(path);
    if (!check.problems.empty()) throw ConfigError(joined(check.problems));
    return std::move(check.config);
}

}  // namespace icewatch::config
