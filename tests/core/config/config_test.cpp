#include "core/config/config.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "core/config/section.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::config {
namespace {

std::string errorOf(const std::string& text) {
    try {
        parseConfig(text, "test.json");
    } catch (const ConfigError& e) {
        EXPECT_EQ(e.code(), kExitConfig);
        return e.what();
    }
    return "";
}

TEST(Config, EmptyObjectGivesDefaults) {
    const Config c = parseConfig("{}", "test.json");
    EXPECT_EQ(c.camera.device, "/dev/video0");
    EXPECT_EQ(c.camera.width, 2560);
    EXPECT_EQ(c.log.level, "info");
}

TEST(Config, ShippedFileDocumentsTheDefaults) {
    // config/icewatch.json documents every key with its default: loading it must give exactly the
    // built-in defaults, or one of the two is lying.
    const Config shipped = loadConfig(test::sourceDir() / "config" / "icewatch.json");
    const Config defaults = parseConfig("{}", "defaults");
    EXPECT_EQ(shipped.camera.device, defaults.camera.device);
    EXPECT_EQ(shipped.camera.format, defaults.camera.format);
    EXPECT_EQ(shipped.camera.width, defaults.camera.width);
    EXPECT_EQ(shipped.camera.height, defaults.camera.height);
    EXPECT_EQ(shipped.camera.fps, defaults.camera.fps);
    EXPECT_EQ(shipped.camera.buffers, defaults.camera.buffers);
    EXPECT_EQ(shipped.camera.frameTimeoutMs, defaults.camera.frameTimeoutMs);
    EXPECT_EQ(shipped.camera.reconnectMinMs, defaults.camera.reconnectMinMs);
    EXPECT_EQ(shipped.camera.reconnectMaxMs, defaults.camera.reconnectMaxMs);
    EXPECT_EQ(shipped.log.level, defaults.log.level);
    const stereo::Parameters& a = shipped.stereo;
    const stereo::Parameters& b = defaults.stereo;
    EXPECT_EQ(a.impulseThreshold, b.impulseThreshold);
    EXPECT_EQ(a.impulseRailThreshold, b.impulseRailThreshold);
    EXPECT_EQ(a.censusGradientThreshold, b.censusGradientThreshold);
    EXPECT_EQ(a.censusAlpha, b.censusAlpha);
    EXPECT_EQ(a.censusAlphaNoiseGain, b.censusAlphaNoiseGain);
    EXPECT_EQ(a.cannyLowThreshold, b.cannyLowThreshold);
    EXPECT_EQ(a.cannyHighThreshold, b.cannyHighThreshold);
    EXPECT_EQ(a.harrisThreshold, b.harrisThreshold);
    EXPECT_EQ(a.lambdaCensus, b.lambdaCensus);
    EXPECT_EQ(a.lambdaAd, b.lambdaAd);
    EXPECT_EQ(a.lambdaGradient, b.lambdaGradient);
    EXPECT_EQ(a.meiLambdaCensus, b.meiLambdaCensus);
    EXPECT_EQ(a.meiLambdaAd, b.meiLambdaAd);
    EXPECT_EQ(a.crossTau1, b.crossTau1);
    EXPECT_EQ(a.crossTau2, b.crossTau2);
    EXPECT_EQ(a.crossL1, b.crossL1);
    EXPECT_EQ(a.crossL2, b.crossL2);
    EXPECT_EQ(a.crossIterations, b.crossIterations);
    EXPECT_EQ(a.scanlinePi1, b.scanlinePi1);
    EXPECT_EQ(a.scanlinePi2, b.scanlinePi2);
    EXPECT_EQ(a.scanlineTau, b.scanlineTau);
    EXPECT_EQ(a.lrMaxDifference, b.lrMaxDifference);
    EXPECT_EQ(a.votingIterations, b.votingIterations);
    EXPECT_EQ(a.votingMinCount, b.votingMinCount);
    EXPECT_EQ(a.votingMinRatio, b.votingMinRatio);
    EXPECT_EQ(a.discontinuityAdjustment, b.discontinuityAdjustment);
    EXPECT_EQ(a.subpixelIntensityRefinement, b.subpixelIntensityRefinement);
    EXPECT_EQ(a.subpixelWindowRadius, b.subpixelWindowRadius);
    EXPECT_EQ(a.subpixelIterations, b.subpixelIterations);
    EXPECT_EQ(a.subpixelMaxChange, b.subpixelMaxChange);
    EXPECT_EQ(a.medianFilter, b.medianFilter);
    EXPECT_EQ(a.sgbmBlockSize, b.sgbmBlockSize);
    EXPECT_EQ(a.sgbmFillHoles, b.sgbmFillHoles);
    EXPECT_EQ(shipped.calibration.file, defaults.calibration.file);
    EXPECT_EQ(shipped.daemon.intervalS, defaults.daemon.intervalS);
    EXPECT_EQ(shipped.daemon.burstFrames, defaults.daemon.burstFrames);
    EXPECT_EQ(shipped.daemon.minFrames, defaults.daemon.minFrames);
    EXPECT_EQ(shipped.daemon.cameraCheckS, defaults.daemon.cameraCheckS);
    EXPECT_EQ(shipped.daemon.stateDir, defaults.daemon.stateDir);
    EXPECT_EQ(shipped.daemon.health.minMeanLevel, defaults.daemon.health.minMeanLevel);
    EXPECT_EQ(shipped.daemon.health.maxSaturatedPercent, defaults.daemon.health.maxSaturatedPercent);
    EXPECT_EQ(shipped.daemon.health.minSharpness, defaults.daemon.health.minSharpness);
    EXPECT_EQ(shipped.daemon.health.minContrast, defaults.daemon.health.minContrast);
    EXPECT_EQ(shipped.alarm.metric, defaults.alarm.metric);
    EXPECT_EQ(shipped.alarm.judge, defaults.alarm.judge);
    EXPECT_EQ(shipped.alarm.warningSet, defaults.alarm.warningSet);
    EXPECT_EQ(shipped.alarm.warningClear, defaults.alarm.warningClear);
    EXPECT_EQ(shipped.alarm.alarmSet, defaults.alarm.alarmSet);
    EXPECT_EQ(shipped.alarm.alarmClear, defaults.alarm.alarmClear);
    EXPECT_EQ(shipped.alarm.warningHoldS, defaults.alarm.warningHoldS);
    EXPECT_EQ(shipped.alarm.alarmHoldS, defaults.alarm.alarmHoldS);
    EXPECT_EQ(shipped.alarm.latch, defaults.alarm.latch);
    EXPECT_EQ(shipped.gpio.chip, defaults.gpio.chip);
    EXPECT_EQ(shipped.gpio.alarmLine, defaults.gpio.alarmLine);
    EXPECT_EQ(shipped.gpio.healthyLine, defaults.gpio.healthyLine);
    EXPECT_EQ(shipped.gpio.activeLow, defaults.gpio.activeLow);
    EXPECT_EQ(shipped.gpio.consumer, defaults.gpio.consumer);
    EXPECT_EQ(shipped.http.enabled, defaults.http.enabled);
    EXPECT_EQ(shipped.http.address, defaults.http.address);
    EXPECT_EQ(shipped.http.port, defaults.http.port);
    EXPECT_EQ(shipped.http.token, defaults.http.token);
    EXPECT_EQ(shipped.history.retentionDays, defaults.history.retentionDays);
    EXPECT_EQ(shipped.pictures.maxThicknessMm, defaults.pictures.maxThicknessMm);
    const volume::Parameters &v = shipped.volume, &d = defaults.volume;
    EXPECT_EQ(v.stereoMethod, d.stereoMethod);
    EXPECT_EQ(v.maxDisparity, d.maxDisparity);
    EXPECT_EQ(v.roiPolygon, d.roiPolygon);
    EXPECT_EQ(v.edgeMarginPx, d.edgeMarginPx);
    EXPECT_EQ(v.segmentationBandMm, d.segmentationBandMm);
    EXPECT_EQ(v.trackRadiusPx, d.trackRadiusPx);
    EXPECT_EQ(v.trackStepPx, d.trackStepPx);
    EXPECT_EQ(v.trackSearchPx, d.trackSearchPx);
    EXPECT_EQ(v.minEvidenceSamples, d.minEvidenceSamples);
    EXPECT_EQ(v.backgroundBandMm, d.backgroundBandMm);
    EXPECT_EQ(v.maxRegistrationMm, d.maxRegistrationMm);
    EXPECT_EQ(v.minSupportSpanPercent, d.minSupportSpanPercent);
    EXPECT_EQ(v.iceMaskGrowPx, d.iceMaskGrowPx);
    EXPECT_EQ(v.outlineGrowthMm, d.outlineGrowthMm);
    EXPECT_EQ(v.outlineIceMinMm, d.outlineIceMinMm);
    EXPECT_EQ(v.outlineFootingMm, d.outlineFootingMm);
    EXPECT_EQ(v.outlineStandoffMm, d.outlineStandoffMm);
    EXPECT_EQ(v.outlineMinTextureGrey, d.outlineMinTextureGrey);
    EXPECT_EQ(v.outlineMinCorrelation, d.outlineMinCorrelation);
    EXPECT_EQ(v.outlineMinContrastGrey, d.outlineMinContrastGrey);
    EXPECT_EQ(v.outlineMaxObliquityDeg, d.outlineMaxObliquityDeg);
    EXPECT_EQ(v.scaleUncertaintyPercent, d.scaleUncertaintyPercent);
    EXPECT_EQ(v.knnK, d.knnK);
    EXPECT_EQ(v.knnTheta, d.knnTheta);
    EXPECT_EQ(v.gridCellMm, d.gridCellMm);
    EXPECT_EQ(v.integration, d.integration);
    EXPECT_EQ(v.maxThicknessMm, d.maxThicknessMm);
    EXPECT_EQ(v.disparityNoisePx, d.disparityNoisePx);
    EXPECT_EQ(v.correlationPx, d.correlationPx);
    EXPECT_EQ(v.subpixelBiasPx, d.subpixelBiasPx);
    EXPECT_EQ(v.trackBiasPx, d.trackBiasPx);
    EXPECT_EQ(v.edgeUncertaintyPx, d.edgeUncertaintyPx);
    EXPECT_EQ(v.facingFatteningPx, d.facingFatteningPx);
    EXPECT_EQ(v.fatteningSeparableStepPx, d.fatteningSeparableStepPx);
    EXPECT_EQ(v.coverageFactor, d.coverageFactor);
    EXPECT_EQ(v.minValidPercent, d.minValidPercent);
    EXPECT_EQ(v.minMeanGrey, d.minMeanGrey);
    EXPECT_EQ(v.maxSaturatedPercent, d.maxSaturatedPercent);
    EXPECT_EQ(v.maxNewSaturatedPercent, d.maxNewSaturatedPercent);
    EXPECT_EQ(v.minContrast, d.minContrast);
    EXPECT_EQ(v.minPoints, d.minPoints);
    EXPECT_EQ(v.maxFilledPercent, d.maxFilledPercent);
}

TEST(Config, VolumeSectionIsRead) {
    const Config c = parseConfig(R"({"volume": {"stereo_method": "sgbm", "integration": "sum", "knn_k": 12,
        "roi_polygon": [0, 0, 10, 0, 10, 10]}})", "test.json");
    EXPECT_EQ(c.volume.stereoMethod, stereo::Method::Sgbm);
    EXPECT_EQ(c.volume.integration, volume::Integration::Sum);
    EXPECT_EQ(c.volume.knnK, 12);
    EXPECT_EQ(c.volume.roiPolygon.size(), 6u);
    EXPECT_EQ(errorOf(R"({"volume": {"integration": "simpson"}})").find("test.json: volume.integration"), 0u);
    EXPECT_EQ(errorOf(R"({"volume": {"roi_polygon": [1, 2, 3]}})").find("test.json: volume.roi_polygon"), 0u);
}

TEST(Config, CalibrationFile) {
    EXPECT_EQ(parseConfig("{}", "test.json").calibration.file, "/etc/icewatch/calibration.yaml");
    EXPECT_EQ(parseConfig(R"({"calibration": {"file": "/srv/box7.yaml"}})", "test.json").calibration.file,
              "/srv/box7.yaml");
    EXPECT_EQ(errorOf(R"({"calibration": {"file": ""}})"), "test.json: calibration.file: must not be empty");
    EXPECT_EQ(errorOf(R"({"calibration": {"path": "x"}})"), "test.json: calibration.path: unknown key");
}

TEST(Config, StereoSectionIsReadAndChecked) {
    const Config c = parseConfig(R"({"stereo": {"census_alpha": 2, "scanline_pi2": 4.5, "median_filter": false}})",
                                 "test.json");
    EXPECT_EQ(c.stereo.censusAlpha, 2);
    EXPECT_EQ(c.stereo.scanlinePi2, 4.5);
    EXPECT_FALSE(c.stereo.medianFilter);
    EXPECT_EQ(errorOf(R"({"stereo": {"scanline_pi2": 11}})"),
              "test.json: stereo.scanline_pi2: must be between 0.0 and 10.0, got 11");
    EXPECT_EQ(errorOf(R"({"stereo": {"cross_tau2": 30}})"), "test.json: stereo.cross_tau2: must not exceed cross_tau1");
    EXPECT_EQ(errorOf(R"({"stereo": {"sgbm_block_size": 4}})"), "test.json: stereo.sgbm_block_size: must be odd");
    EXPECT_EQ(parseConfig(R"({"stereo": {"right_view_scanline_directions": 8}})", "test.json")
                  .stereo.rightViewScanlineDirections,
              8);
    EXPECT_EQ(errorOf(R"({"stereo": {"right_view_scanline_directions": 6}})"),
              "test.json: stereo.right_view_scanline_directions: must be 4 or 8");
    EXPECT_EQ(errorOf(R"({"stereo": {"alpha": 2}})"), "test.json: stereo.alpha: unknown key");
}

TEST(Config, DaemonSectionsAreValidated) {
    EXPECT_EQ(errorOf(R"({"alarm": {"warning_set": 10, "warning_clear": 10}})"),
              "test.json: alarm.warning_clear: must be below warning_set (hysteresis)");
    EXPECT_EQ(errorOf(R"({"alarm": {"metric": "mass"}})"),
              "test.json: alarm.metric: must be one of mean_thickness_mm, volume_mm3, got \"mass\"");
    EXPECT_EQ(errorOf(R"({"alarm": {"judge": "worst"}})"),
              "test.json: alarm.judge: must be one of estimate, upper_bound, got \"worst\"");
    EXPECT_EQ(errorOf(R"({"daemon": {"burst_frames": 2, "min_frames": 3}})"),
              "test.json: daemon.min_frames: must not exceed burst_frames or baseline_frames");
    EXPECT_EQ(errorOf(R"({"daemon": {"health": {"min_contrast": -1}}})"),
              "test.json: daemon.health.min_contrast: must be between 0.0 and 255.0, got -1");
    EXPECT_EQ(errorOf(R"({"gpio": {"alarm_line": 3, "healthy_line": 3}})"),
              "test.json: gpio.healthy_line: must differ from alarm_line");
    EXPECT_EQ(errorOf(R"({"http": {"port": 70000}})"),
              "test.json: http.port: must be between 0 and 65535, got 70000");
    const Config c = parseConfig(R"({"alarm": {"metric": "mean_thickness_mm", "warning_set": 2, "warning_clear": 1,
        "alarm_set": 5, "alarm_clear": 4, "latch": true, "judge": "upper_bound"}, "http": {"token": "s3cret"}})",
                                 "test.json");
    EXPECT_EQ(c.alarm.metric, "mean_thickness_mm");
    EXPECT_EQ(c.alarm.judge, "upper_bound");
    EXPECT_EQ(c.alarm.alarmSet, 5.0);
    EXPECT_TRUE(c.alarm.latch);
    EXPECT_EQ(c.http.token, "s3cret");
}

TEST(Config, MaxRefusedIsThreeIntervalsUnlessSetAndNeverShorterThanOne) {
    EXPECT_EQ(maxRefusedS(parseConfig("{}", "test.json").daemon), 1800);
    EXPECT_EQ(maxRefusedS(parseConfig(R"({"daemon": {"interval_s": 60}})", "test.json").daemon), 180);
    EXPECT_EQ(maxRefusedS(parseConfig(R"({"daemon": {"interval_s": 60, "max_refused_s": 7200}})", "test.json").daemon),
              7200);
    EXPECT_EQ(maxRefusedS(loadConfig(test::sourceDir() / "config" / "icewatch.json").daemon), 1800)
        << "the shipped file documents the default";
    EXPECT_EQ(errorOf(R"({"daemon": {"interval_s": 600, "max_refused_s": 300}})"),
              "test.json: daemon.max_refused_s: must be 0 (three intervals) or at least interval_s");
}

TEST(Config, ReadsValuesAndComments) {
    const Config c = parseConfig(R"({
        // a comment, as the shipped file has
        "camera": {"device": "fake:/tmp/rec", "width": 1280, "height": 480, "controls": {"gain": 4}},
        "log": {"level": "debug"}
    })", "test.json");
    EXPECT_EQ(c.camera.device, "fake:/tmp/rec");
    EXPECT_EQ(c.camera.width, 1280);
    EXPECT_EQ(c.camera.controls.at("gain"), 4);
    EXPECT_EQ(c.log.level, "debug");
}

TEST(Config, UnknownKeyIsNamed) {
    EXPECT_EQ(errorOf(R"({"camera": {"fsp": 30}})"), "test.json: camera.fsp: unknown key");
    EXPECT_EQ(errorOf(R"({"cmaera": {}})"), "test.json: cmaera: unknown key");
}

TEST(Config, WrongTypeIsNamed) {
    EXPECT_EQ(errorOf(R"({"camera": {"fps": "30"}})"), "test.json: camera.fps: must be an integer, got string");
    EXPECT_EQ(errorOf(R"({"camera": {"controls": {"gain": 1.5}}})"),
              "test.json: camera.controls.gain: must be an integer, got 1.5");
    EXPECT_EQ(errorOf(R"({"camera": []})"), "test.json: camera: must be an object, got array");
}

TEST(Config, OutOfRangeIsNamed) {
    EXPECT_EQ(errorOf(R"({"camera": {"fps": 500}})"), "test.json: camera.fps: must be between 1 and 240, got 500");
    EXPECT_EQ(errorOf(R"({"camera": {"width": 1281}})"),
              "test.json: camera.width: must be even: the frame holds two equal eyes side by side");
    EXPECT_EQ(errorOf(R"({"log": {"level": "loud"}})"),
              "test.json: log.level: must be one of debug, error, info, trace, warn, got \"loud\"");
}

TEST(Config, BrokenJsonAndMissingFile) {
    EXPECT_NE(errorOf("{\"camera\": ").find("test.json: not valid JSON"), std::string::npos);
    EXPECT_NE(errorOf("[1, 2]").find("top level must be a JSON object"), std::string::npos);
    try {
        loadConfig("/nonexistent/icewatch.json");
        FAIL() << "a missing file must not load";
    } catch (const ConfigError& e) {
        EXPECT_STREQ(e.what(), "/nonexistent/icewatch.json: cannot read the configuration file");
    }
}

TEST(Config, ANumberNoDoubleHoldsIsAConfigErrorNamingTheKey) {
    // nlohmann::json throws out_of_range for these, which is no parse_error.
    EXPECT_NE(errorOf(R"({"daemon": {"interval_s": 1e999}})").find("test.json: daemon.interval_s: the number 1e999"),
              std::string::npos)
        << errorOf(R"({"daemon": {"interval_s": 1e999}})");
    EXPECT_NE(errorOf(R"({"alarm": {"warning_set": -1e400}})").find("alarm.warning_set: the number -1e400"),
              std::string::npos);
    EXPECT_NE(errorOf(R"({"volume": {"roi_polygon": [1, 2, 3e999]}})").find("volume.roi_polygon[2]: the number"),
              std::string::npos)
        << errorOf(R"({"volume": {"roi_polygon": [1, 2, 3e999]}})");
    // Above INT64_MAX: an unsigned that get<int64_t>() would have wrapped to -1.
    EXPECT_NE(errorOf(R"({"camera": {"controls": {"exposure_time_absolute": 18446744073709551615}}})")
                  .find("camera.controls.exposure_time_absolute: must be an integer"),
              std::string::npos);
    EXPECT_NE(errorOf(R"({"daemon": {"interval_s": 18446744073709551615}})").find("daemon.interval_s: must be between"),
              std::string::npos);
    try {
        loadConfig(test::sourceDir() / "tests/core/config/bad-inputs/overflow.json");
        FAIL() << "must not load";
    } catch (const ConfigError& e) {
        EXPECT_EQ(e.code(), kExitConfig);
    }
}

TEST(Config, ANonLoopbackAddressNeedsAToken) {
    EXPECT_NE(errorOf(R"({"http": {"address": "0.0.0.0", "token": ""}})").find("http.address: \"0.0.0.0\" is reachable"),
              std::string::npos);
    EXPECT_EQ(parseConfig(R"({"http": {"address": "0.0.0.0", "token": "0123456789abcdef"}})", "t").http.address,
              "0.0.0.0");
    EXPECT_EQ(parseConfig(R"({"http": {"address": "10.0.0.2", "token_file": "/etc/icewatch/http-token"}})", "t")
                  .http.address,
              "10.0.0.2");
    EXPECT_EQ(parseConfig(R"({"http": {"address": "127.0.0.2"}})", "t").http.tokenFile, "/etc/icewatch/http-token");
    EXPECT_EQ(parseConfig(R"({"http": {"address": "0.0.0.0", "enabled": false}})", "t").http.enabled, false);
}

TEST(Config, TheGpioSectionAloneIsReadFromAnyFile) {
    const auto dir = test::freshTempDir();
    std::ofstream(dir / "broken.json") << R"({"daemon": {"interval_s": 1e999}, "gpio": {"chip": "fake", "alarm_line": 5}})";
    std::string problem;
    GpioConfig gpio = loadGpioSection(dir / "broken.json", problem);
    EXPECT_FALSE(problem.empty()) << "the file does not parse: defaults";
    EXPECT_EQ(gpio.chip, GpioConfig{}.chip);
    std::ofstream(dir / "other.json") << R"({"daemon": {"interval_s": "often"}, "gpio": {"chip": "fake", "alarm_line": 5}})";
    problem.clear();
    gpio = loadGpioSection(dir / "other.json", problem);
    EXPECT_TRUE(problem.empty()) << problem;
    EXPECT_EQ(gpio.chip, "fake");
    EXPECT_EQ(gpio.alarmLine, 5);
    problem.clear();
    gpio = loadGpioSection(dir / "absent.json", problem);
    EXPECT_FALSE(problem.empty());
    EXPECT_EQ(gpio.alarmLine, GpioConfig{}.alarmLine);
}

TEST(Config, EveryProblemIsReportedNotOnlyTheFirst) {
    const std::string error = errorOf(R"({"camera": {"fps": 0, "width": 641, "colour": 1},
                                         "daemon": {"interval_s": "often"},
                                         "alarm": "loud",
                                         "pictures": {"max_thickness_mm": -1}})");
    for (const char* problem : {"test.json: camera.fps: must be between", "test.json: camera.width: must be even",
                                "test.json: camera.colour: unknown key", "test.json: daemon.interval_s: must be an integer",
                                "test.json: alarm: must be an object", "test.json: pictures.max_thickness_mm: must be between"}) {
        EXPECT_NE(error.find(problem), std::string::npos) << problem << " in:\n" << error;
    }
    const auto dir = test::freshTempDir();
    std::ofstream(dir / "two.json") << R"({"camera": {"fps": 0}, "http": {"port": -1}})";
    const ConfigCheck check = checkConfigFile(dir / "two.json");
    ASSERT_EQ(check.problems.size(), 2u);
    EXPECT_NE(check.problems[0].find("camera.fps"), std::string::npos);
    EXPECT_NE(check.problems[1].find("http.port"), std::string::npos);
    EXPECT_EQ(check.config.camera.fps, CameraConfig{}.fps) << "a wrong value keeps the default";
}

TEST(Config, RelativePathsMeanTheFilesOwnDirectory) {
    const auto dir = test::freshTempDir() / "site";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "icewatch.json") << R"({"calibration": {"file": "calib/box7.yaml"},
        "camera": {"device": "fake:recording"}, "daemon": {"state_dir": "state"},
        "http": {"token_file": "/etc/icewatch/http-token"}, "gpio": {"chip": "fake:gpio.log"}})";
    const Config c = loadConfig(dir / "icewatch.json");
    EXPECT_EQ(c.calibration.file, (dir / "calib/box7.yaml").string());
    EXPECT_EQ(c.camera.device, "fake:" + (dir / "recording").string());
    EXPECT_EQ(c.daemon.stateDir, (dir / "state").string());
    EXPECT_EQ(c.http.tokenFile, "/etc/icewatch/http-token") << "absolute paths stay";
    EXPECT_EQ(c.gpio.chip, "fake:" + (dir / "gpio.log").string());
    // Names that are not paths stay as they are.
    std::ofstream(dir / "real.json") << R"({"camera": {"device": "/dev/video2"}, "gpio": {"chip": "gpiochip0"}})";
    const Config real = loadConfig(dir / "real.json");
    EXPECT_EQ(real.camera.device, "/dev/video2");
    EXPECT_EQ(real.gpio.chip, "gpiochip0");
}

TEST(Config, PicturesSection) {
    EXPECT_EQ(parseConfig(R"({"pictures": {"max_thickness_mm": 25}})", "test.json").pictures.maxThicknessMm, 25.0);
    EXPECT_EQ(errorOf(R"({"pictures": {"scale": 1}})"), "test.json: pictures.scale: unknown key");
}

}  // namespace
}  // namespace icewatch::config
